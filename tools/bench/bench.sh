#!/bin/sh
# bench.sh -- `make bench`: every figure measured in this one run, absolute and as ratios (OpenCV, memcpy, Python, the device's own timing).
set -eu
B=${1:-build}
T=$(mktemp -d /tmp/sonard-bench.XXXXXX)
trap 'rm -rf "$T"' EXIT
"$B/bench" "$T" > "$T/c.txt"
"$B/bench_opencv" "$T" > "$T/cv.txt"
"$B/sonar-sim" --scene pool --out "$T/pool.csv" --truth "$T/pool.json"
rows=$(wc -l < "$T/pool.csv")
# --replay wall time (whole process: load, parse, filter, detect, JSON), best of 3
best=999999
for i in 1 2 3; do
    s=$(date +%s%N); "$B/sonard" --replay "$T/pool.csv" --json --quiet --log-level warn > /dev/null; e=$(date +%s%N)
    ms=$(( (e - s) / 1000000 )); [ "$ms" -lt "$best" ] && best=$ms
done
echo "replay_ms $best" >> "$T/c.txt"
.venv/bin/python tools/eval/study_pipeline.py "$T/pool.csv" --range 12 > "$T/py.txt"
v() { awk -v k="$1" '$1 == k { print $2 }' "$T/c.txt" "$T/cv.txt"; }
py_total=$(awk '{for (i = 1; i < NF; i++) if ($i == "total_s") print $(i + 1)}' "$T/py.txt")
py_filt=$(awk '{for (i = 1; i < NF; i++) if ($i == "load_to_filtered_s") print $(i + 1)}' "$T/py.txt")
awk -v med="$(v median5_ns_per_sample)" -v cvrow="$(v cv_median5_row_ns_per_sample)" \
    -v m55="$(v median5x5_ns_per_sample)" -v cv55="$(v cv_median5x5_ns_per_sample)" \
    -v step="$(v beam_step_us)" -v gstep="$(v beam_step_global_us)" -v cpy="$(v memcpy_beam_us)" -v bg="$(v background_beam_us)" \
    -v det="$(v sweep_detect_ms)" -v detw="$(v sweep_detect_worst_ms)" -v km="$(v kmeans_hull_5000_ms)" \
    -v cvkm="$(v cv_kmeans_hull_5000_ms)" -v rep="$best" -v rows="$rows" -v pyt="$py_total" -v pyf="$py_filt" \
    -v cvv="$(v cv_version)" -v trk="$(v tracker_sweep_us)" -v ntrk="$(v tracker_tracks)" -v trkcv="$(v tracker_sweep_cv_us)" -v trkact="$(v tracker_activity_sweep_us)" \
    -v wbg="$(v world_background_beam_us)" -v obs="$(v obstacle_beam_us)" \
    -v obsmap="$(v obstacle_map_us)" -v obsn="$(v obstacle_map_echoes)" \
    -v svload="$(v survey_load_ms)" -v svstep="$(v beam_step_survey_us)" -v svuse="$(v beam_step_survey_in_use)" \
    -v svfile="$(awk '$1 == "survey_file_bytes" { print $2 }' "$T/c.txt")" -v lvfile="$(awk '$1 == "survey_file_bytes" { print $3 }' "$T/c.txt")" \
    -v svram="$(awk '$1 == "survey_ram_bytes" { print $2 + $3 }' "$T/c.txt")" -v lvram="$(awk '$1 == "survey_ram_bytes" { print $2 }' "$T/c.txt")" 'BEGIN {
    beam_ms = 19.4 + 6.0 + 2.0 * 12 / 1500 * 1000;   # device timing model at 12 m, 1-grad steps (ping.md section 3)
    printf "sonard bench (one run; 400 x 1200 sweep, gcc -O2, OpenCV %s single-threaded)\n", cvv
    printf "%-46s %14s %14s %10s\n", "stage", "sonard", "reference", "ratio"
    printf "%-46s %11.3f ns %11.3f ns %9.1fx  (OpenCV medianBlur on the same 1x1200 rows)\n", "median-5 along range, per sample", med, cvrow, cvrow / med
    printf "%-46s %11.3f ns %11.3f ns %9.2fx  (OpenCV medianBlur 5x5 on the sweep; <1 = slower)\n", "median 5x5 over the sweep, per sample", m55, cv55, cv55 / m55
    printf "%-46s %11.3f us %11.3f us %9.1fx  (memcpy of the same 1200 bytes)\n", "per-beam step, global threshold (as the study)", gstep, cpy, gstep / cpy
    printf "%-46s %11.3f us %11.3f us %9.2fx  (OpenCV medianBlur alone on the beam; target <= 1)\n", "  the same vs OpenCV medianBlur alone", gstep, cvrow * 1.2, gstep / (cvrow * 1.2)
    printf "%-46s %11.3f us\n", "  of which background update+subtract", bg
    printf "%-46s %11.3f us %11.3f us %9.2fx  (the global step; target <= 1.54: 0.6 against 0.39 us)\n", "per-beam step, default (auto bg, CFAR, runs)", step, gstep, step / gstep
    printf "%-46s %11.3f us %11.3f us %9.3fx  (the default step; target <= 1.10%s)\n", "  the same judged against a site survey", svstep, step, svstep / step, (svuse == 1 ? "" : "; NOT IN USE: not measured")
    printf "%-46s %11.3f ms %11.3f ms %9.0fx  (device: one beam at 12 m; once, at start)\n", "  loading it (CRC, levels, spread, structure)", svload, beam_ms, beam_ms / svload
    printf "%-46s %11.0f B  %11.0f B  %9.2fx  (the levels alone, a learnt model; target <= 2)\n", "  the survey file, levels and spread", svfile, lvfile, svfile / lvfile
    printf "%-46s %11.0f B  %11.0f B  %9.2fx  (the levels alone; target <= 2)\n", "  its RAM in use, levels and spread", svram, lvram, svram / lvram
    printf "%-46s %11.3f ms %11.3f ms %9.0fx  (device: one beam at 12 m, 1-grad steps)\n", "sweep detection, typical (20 moving objects)", det, beam_ms, beam_ms / det
    printf "%-46s %11.3f ms\n", "sweep detection, worst (1024 runs, 16 pieces)", detw
    printf "%-46s %11.3f ms %11.3f ms %9.2fx  (OpenCV kmeans PP + convexHull)\n", "k-means + hull, 5000 points, 6 clusters", km, cvkm, cvkm / km
    printf "%-46s %11.3f us %11.3f ms %9.0fx  (device: one beam at 12 m; target <= 50 us)\n", "tracker, 16 detections, " ntrk " tracks, a sweep", trk, beam_ms, beam_ms * 1000 / trk
    printf "%-46s %11.3f us %11.3f us %9.2fx  (the tracker before issue 37: cv, each sweep final; <1 = slower)\n", "  the same against one model, no deferral", trk, trkcv, trkcv / trk
    printf "%-46s %11.3f us %11.3f us %9.2fx  (the tracker alone; issue 46 target <= 1.25x)\n", "  the same with each track'"'"'s activity look", trkact, trk, trkact / trk
    printf "%-46s %11.3f us %11.3f us %9.1fx  (the per-angle model on the same beams; target <= 50 us)\n", "background in the world grid (moving), per beam", wbg, bg, wbg / bg
    printf "%-46s %11.3f us %11.3f ms %9.0fx  (device: one beam at 12 m)\n", "  the same against the device", wbg, beam_ms, beam_ms * 1000 / wbg
    printf "%-46s %11.3f us %11.3f ms %9.0fx  (device: one beam at 12 m)\n", "OBSTACLE_DISTANCE map (nearest echo), per beam", obs, beam_ms, beam_ms * 1000 / obs
    printf "%-46s %11.3f us %11.3f ms %9.0fx  (its period at 20 Hz)\n", "  one message'"'"'s map from " obsn " world points", obsmap, 50.0, 50000 / obsmap
    printf "%-46s %11.1f ms %11.1f ms %9.0fx  (the study'"'"'s Python pipeline, load to detections)\n", "--replay of " rows " rows (whole process)", rep, pyt * 1000, pyt * 1000 / rep
    printf "%-46s %14s %11.1f ms\n", "  Python load to end of filtering (paper'"'"'s def.)", "", pyf * 1000
    printf "targets: survey step <= 1.10x the default: %s; tracker <= 50 us a sweep: %s; tracker with activity <= 1.25x it: %s; global step <= 0.5 us: %s; <= OpenCV medianBlur alone: %s; default step <= 1.54x the global: %s; world background <= 50 us: %s; 5x5 median at least as fast as OpenCV: %s; sweep detection <= 1 ms: %s; replay >= 100x Python: %s\n",
        (svuse == 1 && svstep <= 1.10 * step ? "met" : "MISSED"), (trk <= 50 ? "met" : "MISSED"), (trkact <= 1.25 * trk ? "met" : "MISSED"), (gstep <= 0.5 ? "met" : "MISSED"), (gstep <= cvrow * 1.2 ? "met" : "MISSED"),
        (step <= 1.54 * gstep ? "met" : "MISSED"), (wbg <= 50 ? "met" : "MISSED"), (m55 <= cv55 ? "met" : "MISSED"),
        (detw <= 1.0 ? "met" : "MISSED"), (pyt * 1000 / rep >= 100 ? "met" : "MISSED")
}'
echo
python3 tools/bench/bench_live.py "$B"
echo
sh tools/bench/bench_mavlink.sh "$B"
echo
if [ -x .venv-ros2/bin/python ]; then sh tools/bench/ros2_cost.sh "$B"; else echo "bench: the ROS 2 bridge not measured: no .venv-ros2 (make ros2, then make ros2-cost)"; fi
