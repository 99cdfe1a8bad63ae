// view.js -- draws sonard's beams into a polar fan as they come (one WebSocket), with range rings, hulls, track IDs
// and trails, and a health panel; plain JavaScript, no libraries. window.sonarView exposes the state for tests.
// Cockpit's fan widget (widget_fan.html) runs it too: a page without the panel's table or the filtered switch.
"use strict";

const S = 720, C = S / 2, R = S / 2 - 12;           // canvas, centre, fan radius in pixels
const LINK = ["down", "connecting", "probing", "scanning", "auto-transmit", "stopping", "stopped", "passive"];
const image = document.getElementById("image"), overlay = document.getElementById("overlay");
const ictx = image.getContext("2d"), octx = overlay.getContext("2d");
const img = ictx.createImageData(S, S);
const px32 = new Uint32Array(img.data.buffer);

// A thermal palette in the spirit of Ping Viewer's: black, blue, cyan, yellow, red, white.
const stops = [[0, 0, 0, 0], [40, 0, 20, 110], [100, 0, 170, 200], [160, 240, 230, 40], [215, 240, 60, 20], [255, 255, 255, 255]];
const palette = new Uint32Array(256);
for (let v = 0; v < 256; v++) {
  let k = 0;
  while (stops[k + 1][0] < v) k++;
  const a = stops[k], b = stops[k + 1], t = (v - a[0]) / (b[0] - a[0]);
  const ch = i => Math.round(a[i] + (b[i] - a[i]) * t);
  palette[v] = (255 << 24) | (ch(3) << 16) | (ch(2) << 8) | ch(1);   // little-endian RGBA
}
const EMPTY = (255 << 24) | (0x1a << 16) | (0x14 << 8) | 0x10;      // outside the fan and not yet swept
px32.fill(EMPTY);

// Each pixel of the fan belongs to the nearest gradian; per angle, its pixels and their radial fractions.
const byAngle = [];
for (let a = 0; a < 400; a++) byAngle.push({ idx: [], frac: [] });
for (let py = 0; py < S; py++) {
  for (let pxl = 0; pxl < S; pxl++) {
    const x = (C - py) / R, y = (pxl - C) / R, r = Math.hypot(x, y);    // x forward (up), y starboard (right)
    if (r >= 1) continue;
    let a = Math.round(Math.atan2(y, x) * 200 / Math.PI);
    a = ((a % 400) + 400) % 400;
    byAngle[a].idx.push(py * S + pxl);
    byAngle[a].frac.push(r);
  }
}
for (const e of byAngle) { e.idx = Int32Array.from(e.idx); e.frac = Float32Array.from(e.frac); }

const view = window.sonarView = {
  beams: 0, frames: 0, firstDrawMs: null, range: 0, state: "connecting", silent_s: null, status: null, viewInfo: null,
  detections: [], tracks: [], trails: new Map(), dropped: 0, revisions: 0, survey: null, surveyText: "", clutter: null,
  stats: { fps: 0, latency_ms_mean: null, latency_ms_max: null, latency_n: 0 },
  background: [0x10, 0x14, 0x1a],
  toPixel(x, y) { const k = view.range > 0 ? R / view.range : 0; return [Math.round(C + y * k), Math.round(C - x * k)]; },
  resetStats() { latSum = 0; latMax = 0; latN = 0; },
  pixelAt(x, y) { const [u, v] = view.toPixel(x, y); const d = ictx.getImageData(u, v, 1, 1).data; return [d[0], d[1], d[2]]; },
};

let received = 0, acked = 0, ackedAt = 0;
let dirty = false, newestUtime = 0, latSum = 0, latMax = 0, latN = 0, prevAngle = -1, width = 1;
const beamTimes = [];

function drawBeam(buf) {
  const dv = new DataView(buf);
  const angle = dv.getUint16(1, true), range = dv.getFloat32(3, true), utime = dv.getFloat64(7, true), n = dv.getUint16(15, true);
  const s = new Uint8Array(buf, 17, n);
  if (Math.abs(range - view.range) > 1e-3) { view.range = range; }
  // A beam covers the step to its neighbours: the gradians between it and the previous beam (the short way round).
  if (prevAngle >= 0) {
    let d = Math.abs(angle - prevAngle); if (d > 200) d = 400 - d;
    if (d >= 1 && d <= 10) width = d;
  }
  prevAngle = angle;
  const lo = angle - ((width - 1) >> 1);
  for (let k = 0; k < width; k++) {
    const e = byAngle[(lo + k + 400) % 400];
    for (let i = 0; i < e.idx.length; i++) px32[e.idx[i]] = palette[s[Math.min(n - 1, (e.frac[i] * n) | 0)]];
  }
  view.beams++;
  beamTimes.push(performance.now());
  if (utime > newestUtime) newestUtime = utime;
  dirty = true;
}

function rings() {
  octx.clearRect(0, 0, S, S);
  if (!(view.range > 0)) return;
  const k = R / view.range, steps = [0.5, 1, 2, 5, 10, 20];
  const step = steps.find(st => view.range / st <= 6) || 20;
  octx.strokeStyle = "rgba(200,220,255,0.35)"; octx.fillStyle = "rgba(200,220,255,0.8)"; octx.lineWidth = 1;
  octx.font = "11px system-ui";
  for (let m = step; m <= view.range + 1e-6; m += step) {
    octx.beginPath(); octx.arc(C, C, m * k, 0, 2 * Math.PI); octx.stroke();
    octx.fillText(m + " m", C + 3, C - m * k + 12);
  }
  octx.beginPath(); octx.moveTo(C, C); octx.lineTo(C, C - R); octx.stroke();   // forward
}

// The survey's structure (walls, ropes, a ladder: what is never an object), in grey under everything else.
function surveyShapes() {
  const sv = view.survey;
  if (!sv || sv.state !== 1) return;
  octx.lineWidth = 1.5; octx.strokeStyle = "rgba(150,160,170,0.75)"; octx.fillStyle = "rgba(150,160,170,0.18)";
  for (const p of sv.places) {
    if (!p.hull.length) continue;
    octx.beginPath();
    p.hull.forEach(([x, y], i) => { const [u, v] = view.toPixel(x, y); i ? octx.lineTo(u, v) : octx.moveTo(u, v); });
    octx.closePath(); octx.fill(); octx.stroke();
  }
}

// What the status says of the site's survey, for people.
const SURVEY_WHY = { 2: "another range or samples", 3: "another gain", 5: "the mount turned", 6: "the structure moved",
                     7: "too much stands out", 8: "a moving sonar", 9: "the background restarted", 10: "structure it does not hold" };
function surveyText(st) {
  if (!st || !st.survey_state) return "no survey: learning";
  const when = new Date(st.survey_utime / 1000).toISOString().slice(0, 16).replace("T", " ") + " UTC";
  const what = st.survey_fixed ? "survey of " + when : "learnt model of " + when;
  if (st.survey_state === 1) return what;
  const why = st.survey_why === 5 ? `the mount turned by about ${st.survey_turn_grad} gradians` : (SURVEY_WHY[st.survey_why] || "?");
  return `${what} does not fit (${why}): learning`;
}

// The clutter map (switched on by the page's box): each cell of range band x bearing sector shaded by its density
// above the quietest cell's, against the densest, in violet (no other mark is) under everything else; a cell never
// looked at, or with nothing learnt, is left clear.
function clutterLayer() {
  const box = document.getElementById("clutter"), m = view.clutter;
  if (!box || !box.checked || !m || !(view.range > 0)) return;
  // shaded from the quietest cell looked at (the site's mean, where nothing was learnt) to the densest
  const seen = m.density.filter(d => d > 0), k = R / view.range, w = m.range_m / m.bands * k;
  const low = Math.min(...seen), peak = Math.max(...seen);
  if (!(peak > low)) return;
  for (let b = 0; b < m.bands; b++) {
    for (let s = 0; s < m.sectors; s++) {
      const d = m.density[b * m.sectors + s] - low;
      if (!(d > 0)) continue;
      // gradians clockwise from forward (up) -> canvas angle from +x (right), clockwise: 0 gradians is -90 degrees
      const a0 = (s * 400 / m.sectors) * Math.PI / 200 - Math.PI / 2, a1 = ((s + 1) * 400 / m.sectors) * Math.PI / 200 - Math.PI / 2;
      octx.fillStyle = `rgba(230,60,255,${(0.6 * Math.sqrt(d / (peak - low))).toFixed(3)})`;
      octx.beginPath(); octx.arc(C, C, (b + 1) * w, a0, a1); octx.arc(C, C, b * w, a1, a0, true); octx.closePath(); octx.fill();
    }
  }
}

function shapes() {
  clutterLayer();
  surveyShapes();
  octx.lineWidth = 2;
  for (const d of view.detections) {
    if (!d.hull.length) continue;
    // objects in red (orange: there and still since the first look, with no survey to say it is no object);
    // structure (walls, ropes, what was learnt as structure) dashed grey; a wall's echo behind it dotted, darker
    octx.strokeStyle = d.echo ? "rgba(120,120,130,0.6)" : d.structure ? "rgba(190,190,190,0.7)" : d.since_start ? "#ffa657" : "#ff5c5c";
    octx.setLineDash(d.echo ? [2, 4] : d.structure ? [5, 4] : []);
    octx.beginPath();
    d.hull.forEach(([x, y], i) => { const [u, v] = view.toPixel(x, y); i ? octx.lineTo(u, v) : octx.moveTo(u, v); });
    octx.closePath(); octx.stroke();
  }
  octx.setLineDash([]);
  octx.font = "bold 13px system-ui";
  for (const t of view.tracks) {
    const trail = view.trails.get(t.id) || [];
    octx.strokeStyle = "rgba(90,200,255,0.8)"; octx.lineWidth = 1.5;
    octx.beginPath();
    trail.forEach(([x, y], i) => { const [u, v] = view.toPixel(x, y); i ? octx.lineTo(u, v) : octx.moveTo(u, v); });
    octx.stroke();
    const [u, v] = view.toPixel(t.x, t.y);
    // what it is: structure grey, resting (moved, now still: the pool watcher's case) amber, else blue; dim unless hit
    const hue = t.what === "still" ? "#9aa5b1" : t.what === "resting" ? "#ffb347" : "#5ac8ff";
    octx.fillStyle = t.state === 1 ? hue : "#6b7580";
    octx.beginPath(); octx.arc(u, v, 4, 0, 2 * Math.PI); octx.fill();
    // what it is doing (standing, struggling) where known, else what it is; an alarm in red capitals
    const act = t.activity === "standing" || t.activity === "struggling" ? t.activity : "";
    const alarm = (t.alarms || []).map(a => a.toUpperCase()).join(" ");
    octx.fillStyle = alarm ? "#ff4040" : octx.fillStyle;
    octx.fillText("#" + t.id + (act ? " " + act : t.what && t.what !== "new" && t.what !== "moving" ? " " + t.what : "")
                  + (t.what === "resting" || act === "standing" ? " " + Math.round(t.still_s) + " s" : "")
                  + (alarm ? " " + alarm : ""), u + 6, v - 6);
  }
}

function frame() {
  if (dirty) {
    ictx.putImageData(img, 0, 0);
    dirty = false;
    view.frames++;
    if (view.firstDrawMs == null) view.firstDrawMs = performance.now();   // since the page's navigation began
    // latency behind the sonar: the newest beam on screen against the wall clock (sonard stamps beams on arrival)
    const lat = Date.now() - newestUtime / 1000;
    if (lat > -1000 && lat < 60000) { latSum += lat; latN++; latMax = Math.max(latMax, lat); }
  }
  rings();
  shapes();
  // flow control: tell the server what arrived, so it sends no more than it can draw soon; at most ten times a second
  // unless a quarter of the server's window (8 of 32 beams) is waiting, so the acknowledgements cost it little
  const now = performance.now();
  if (received !== acked && ws && ws.readyState === 1 && (received - acked >= 8 || now - ackedAt >= 100)) {
    ws.send(JSON.stringify({ received })); acked = received; ackedAt = now;
  }
  requestAnimationFrame(frame);
}
requestAnimationFrame(frame);

function row(name, value, bad) { return `<tr><td>${name}</td><td class="${bad ? "bad" : ""}">${value}</td></tr>`; }

let lastFrames = 0;
setInterval(() => {
  const now = performance.now();
  while (beamTimes.length && beamTimes[0] < now - 1000) beamTimes.shift();
  view.stats.fps = view.frames - lastFrames; lastFrames = view.frames;
  view.stats.latency_ms_mean = latN ? latSum / latN : null; view.stats.latency_ms_max = latN ? latMax : null;
  view.stats.latency_n = latN;
  const st = view.status, vi = view.viewInfo || {};
  const silent = vi.silent_s;
  view.silent_s = silent;
  let state;
  if (view.state === "offline") state = `<span class="bad">view server unreachable: retrying</span>`;
  else if (silent == null) state = "waiting for sonard…";
  else if (silent > 3) state = `<span class="bad">no data from sonard for ${silent.toFixed(0)} s</span>`;
  else state = `<span class="ok">live</span>`;
  document.getElementById("state").innerHTML = state;
  let h = "";
  view.surveyText = surveyText(st);
  document.getElementById("survey").innerHTML = view.surveyText;
  document.getElementById("survey").className = st && st.survey_state === 2 ? "bad" : "";
  if (st) {
    h += row("link", `${LINK[st.link_state] || st.link_state} ${st.link}`, st.link_state < 3);
    if (st.passive) h += row("driving program", st.passive_idle ? "quiet (no beams)" : "beams coming", st.passive_idle > 0);
    h += row("firmware", `${st.fw_major}.${st.fw_minor}.${st.fw_patch}`);
    h += row("sweep time", st.last_sweep_s > 0 ? st.last_sweep_s.toFixed(1) + " s" : "—");
    h += row("processing a beam p50 / p99", `${st.beam_us_p50.toFixed(1)} / ${st.beam_us_p99.toFixed(1)} µs`);
    h += row("sweeps", st.sweeps);
    h += row("tracks", st.tracks);
    for (const k of ["checksum_errors", "timeouts", "retries", "nacks", "reconnects", "off_angle", "beams_rejected", "sink_errors",
                     "blank_beams", "interference_beams"])
      h += row(k.replace(/_/g, " "), st[k] || 0, st[k] > 0 && k !== "retries");
  }
  h += row("beams / s", beamTimes.length);
  h += row("frames / s", view.stats.fps);
  h += row("latency behind sonar", view.stats.latency_ms_mean == null ? "—" : view.stats.latency_ms_mean.toFixed(0) + " ms");
  h += row("view: dropped (behind)", vi.dropped || 0, false);
  h += row("view: malformed messages", vi.bad || 0, (vi.bad || 0) > 0);
  if (document.getElementById("stats")) document.getElementById("stats").innerHTML = h;
}, 1000);

let ws = null;
function connect() {
  // relative to the page, so the view works under a proxy's prefix (BlueOS: /extensionv2/sonard/)
  ws = new WebSocket(new URL("ws", location.href).href.replace(/^http/, "ws"));
  ws.binaryType = "arraybuffer";
  const filtered = document.getElementById("filtered");
  ws.onopen = () => { view.state = "open"; received = acked = 0; ws.send(JSON.stringify({ filtered: filtered ? filtered.checked : false })); };
  ws.onmessage = ev => {
    if (typeof ev.data !== "string") { drawBeam(ev.data); received++; return; }
    const m = JSON.parse(ev.data);
    if (m.kind === "detections") view.detections = m.detections;
    else if (m.kind === "tracks") {
      // a revision of the last sweep's IDs: that trail was the other track's all along
      const moved = (m.revisions || []).map(r => [r.now, view.trails.get(r.id)]);
      for (const [now, tr] of moved) if (now && tr) view.trails.set(now, tr);
      view.revisions += (m.revisions || []).length ? 1 : 0;
      view.tracks = m.tracks;
      const seen = new Set();
      for (const t of m.tracks) {
        seen.add(t.id);
        const tr = view.trails.get(t.id) || [];
        tr.push([t.x, t.y]); if (tr.length > 8) tr.shift();
        view.trails.set(t.id, tr);
      }
      for (const id of [...view.trails.keys()]) if (!seen.has(id)) view.trails.delete(id);
    } else if (m.kind === "status") view.status = m.status;
    else if (m.kind === "survey") view.survey = m;
    else if (m.kind === "clutter") view.clutter = m;
    else if (m.kind === "view") view.viewInfo = m;
  };
  ws.onclose = () => { view.state = "offline"; setTimeout(connect, 1000); };
}
if (document.getElementById("filtered")) document.getElementById("filtered").onchange = e => {
  px32.fill(EMPTY); dirty = true;
  if (ws && ws.readyState === 1) ws.send(JSON.stringify({ filtered: e.target.checked }));
};
connect();
