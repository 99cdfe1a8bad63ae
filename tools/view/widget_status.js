// widget_status.js -- Cockpit's sonard status tile: the view server's stream without beams (it asks for none), turned
// into a few lines a pilot reads at a glance and two alarms: a track still too long, and a lost sonar. Plain JavaScript.
// window.sonarStatus exposes the state for tests.
"use strict";

const LINK = ["down", "connecting", "probing", "scanning", "auto-transmit", "stopping", "stopped", "passive"];
const REC = ["", "recording", "written, in use", "refused", "cancelled", "failed"];
const st = window.sonarStatus = {
  status: null, view: null, detections: [], tracks: [], beamsPerS: null, alarms: [], rows: {}, updates: 0, open: false,
  firstStatusMs: null,   // since the page's navigation began: when the first status was drawn
};
let prev = null;   // the previous status: beams per second from its counter

const esc = t => String(t).replace(/[&<>"]/g, c => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);

// What the status says of the survey, with a recording's progress or its end.
function survey(s) {
  if (!s) return "—";
  let t = !s.survey_state ? "none: learning" : s.survey_state === 1 ? (s.survey_fixed ? "in use" : "learnt model in use")
        : "does not fit: learning";
  if (s.survey_rec === 1) t = `recording ${s.survey_rec_sweeps} of ${s.survey_rec_of} sweeps (keep the site empty)`;
  else if (s.survey_rec >= 2) t += ` · last recording ${REC[s.survey_rec]}` + (s.survey_rec_said ? `: ${s.survey_rec_said}` : "");
  return t;
}

function draw() {
  const s = st.status, v = st.view || {}, rows = {};
  const silent = v.silent_s;
  const lost = st.open === false || silent == null || silent > 3 || (s && ![3, 4, 7].includes(s.link_state));
  rows.link = !st.open ? "view server unreachable" : silent == null ? "waiting for sonard"
            : silent > 3 ? `no data from sonard for ${silent.toFixed(0)} s`
            : s ? `${LINK[s.link_state] || s.link_state}` + (s.link ? ` (${s.link})` : "") : "live";
  rows["beams / s"] = st.beamsPerS == null ? "—" : st.beamsPerS.toFixed(1);
  const objs = st.detections.filter(d => !d.structure);
  let near = null;
  for (const d of objs) {
    const r = Math.hypot(d.x, d.y);
    if (!near || r < near.r) near = { r, b: Math.atan2(d.y, d.x) * 180 / Math.PI };
  }
  rows["nearest object"] = near ? `${near.r.toFixed(1)} m at ${near.b >= 0 ? "+" : ""}${near.b.toFixed(0)}° (starboard +)` : "none";
  // A track that never moved is the site's structure while nothing says otherwise; with the survey in use the
  // survey holds the structure, so such a track is an object that has not moved (someone standing, or worse).
  const surveyed = s && s.survey_state === 1;
  // A track sonard says stands or struggles is a person whatever its kind.
  const live = st.tracks.filter(t => surveyed || (t.what !== "still" && t.what !== "static since start") ||
                                     t.activity === "standing" || t.activity === "struggling");
  rows["objects / tracks"] = `${objs.length} in the last sweep / ${live.length} tracked`;
  const acts = ["moving", "standing", "struggling"].map(a => [a, st.tracks.filter(t => t.activity === a).length]);
  rows["activity"] = acts.map(([a, n]) => `${n} ${a}`).join(", ");
  let still = null;
  for (const t of live) if (t.still_s > 0 && (!still || t.still_s > still.still_s)) still = t;
  rows["stillest track"] = still ? `#${still.id} still ${Math.round(still.still_s)} s` : "none still";
  rows.survey = survey(s);
  const alarms = [];
  const limit = v.still_alarm_s || 60;
  // sonard's own alarms first: struggling in 2 of the last 3 looks; still past its --still-alarm
  for (const t of st.tracks) if ((t.alarms || []).includes("struggle"))
    alarms.push(`STRUGGLE: track #${t.id} struggling at ${Math.hypot(t.x, t.y).toFixed(1)} m, ${(Math.atan2(t.y, t.x) * 180 / Math.PI).toFixed(0)}°`);
  for (const t of live) if ((t.alarms || []).includes("still") || t.still_s > limit)
    alarms.push(`STILL: track #${t.id} still ${t.still_s.toFixed(1)} s` + ((t.alarms || []).includes("still") ? " (sonard's alarm)" : ` (> ${limit} s)`));
  if (lost && st.updates > 0) alarms.push("SONAR LOST: " + rows.link);
  st.alarms = alarms;
  st.rows = rows;
  document.getElementById("alarms").innerHTML = alarms.map(esc).join("<br>");
  const bad = { link: lost, survey: s && (s.survey_state === 2 || s.survey_rec === 3 || s.survey_rec === 5) };
  document.getElementById("rows").innerHTML = Object.entries(rows)
    .map(([k, x]) => `<tr><td>${esc(k)}</td><td class="${bad[k] ? "bad" : ""}">${esc(x)}</td></tr>`).join("");
  st.updates++;
}

function connect() {
  const ws = new WebSocket(new URL("ws", location.href).href.replace(/^http/, "ws"));
  ws.onopen = () => { st.open = true; ws.send(JSON.stringify({ beams: false })); };
  ws.onmessage = ev => {
    if (typeof ev.data !== "string") return;
    const m = JSON.parse(ev.data);
    if (m.kind === "status") {
      const s = m.status;
      if (prev && s.utime > prev.utime && s.beams >= prev.beams)
        st.beamsPerS = (s.beams - prev.beams) / ((s.utime - prev.utime) * 1e-6);
      prev = s;
      st.status = s;
      if (st.firstStatusMs == null) { draw(); st.firstStatusMs = performance.now(); }
    } else if (m.kind === "detections") st.detections = m.detections;
    else if (m.kind === "tracks") st.tracks = m.tracks;
    else if (m.kind === "view") st.view = m;
  };
  ws.onclose = () => { st.open = false; setTimeout(connect, 1000); };
}
connect();
draw();
setInterval(draw, 500);
