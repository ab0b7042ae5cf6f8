#!/usr/bin/env bash
# browser.sh: `make test-browser`: animation pages of `mbcc run --animate`
# played in headless Chromium (Debian's chromium, driven by puppeteer-core,
# pinned in web/package-lock.json) by web/browser_test.mjs: the page loads with
# no console error and no request but itself, every body is in the scene, Play
# advances the frame, Pause and the slider work, the canvas is drawn; on the
# flexible slider-crank, the drawn rod tip (node 8, deformed from the modal
# coordinates) sits on the slider it is jointed to, and the drawn midspan
# deflection equals the simulator's 'midspan' output.  Screenshots go to
# $SHOTS (default $B/browser; SHOTS=docs/img for the documentation).
# About 30 s (two simulations and two browser sessions); exit 0 = pass.
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
B=${B:-build}
case $B in /*) ;; *) B="$root/$B" ;; esac
SHOTS=${SHOTS:-$B/browser}
case $SHOTS in /*) ;; *) SHOTS="$root/$SHOTS" ;; esac
mkdir -p "$SHOTS"
command -v "${CHROMIUM:-chromium}" > /dev/null || { echo "FAIL: no chromium (bash scripts/install-deps.sh installs it)"; exit 1; }
# the test imports puppeteer-core from the npm packages of make web
cp "$root/web/browser_test.mjs" "$B/web/browser_test.mjs" || exit 1

# 1. the rigid slider-crank
if "$MBCC" run "$root/models/slider_crank.yaml" --animate -o sc.csv --plot none --quiet > sc.log 2>&1; then
  cat > sc.json <<EOF
{"html": "sc.html", "screenshot": "$SHOTS/animation_slider_crank.png", "bodies": ["crank", "rod", "slider"],
 "frames": 501, "frame_for_shot": 40}
EOF
  node "$B/web/browser_test.mjs" sc.json || err "the rigid slider-crank page"
else
  err "mbcc run slider_crank --animate failed: $(tail -3 sc.log)"
fi

# 2. the flexible slider-crank: the rod drawn from its modes
if "$MBCC" run "$root/models/slider_crank_flexible.yaml" --animate -o scf.csv --plot none --quiet > scf.log 2>&1; then
  # the simulator's midspan deflection output at a few frames
  frames="50,150,250,350,450"
  values=$(awk -F, -v fr="$frames" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "midspan") c = i
      n = split(fr, f, ","); for (i = 1; i <= n; i++) want[f[i] + 2] = 1; next }
    (NR in want) { printf "%s%s", s, $c; s = "," }' scf.csv)
  cat > scf.json <<EOF
{"html": "scf.html", "screenshot": "$SHOTS/animation_slider_crank_flexible.png", "bodies": ["crank", "rod", "slider"],
 "frames": 501, "frame_for_shot": 120, "scale": 20,
 "joints": [{"name": "wrist_pin", "flexible": "rod", "node": 8, "other": "slider", "point": [0, 0, 0],
             "tolerance": 1e-7}],
 "deflections": [{"name": "midspan", "body": "rod", "node": 4, "chord": [0, 8], "component": 1,
                  "scale": 3.280839895013123, "frames": [$frames], "values": [$values]}]}
EOF
  node "$B/web/browser_test.mjs" scf.json || err "the flexible slider-crank page"
else
  err "mbcc run slider_crank_flexible --animate failed: $(tail -3 scf.log)"
fi
[ $fail = 0 ] && echo "browser tests: ok (screenshots in $SHOTS)"
exit $fail
