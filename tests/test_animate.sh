#!/usr/bin/env bash
# test_animate.sh: `mbcc run --animate` and `mbcc animate` (exit 0 = pass; a
# few seconds).  The page itself is played in headless Chromium by
# tests/browser.sh (make test-browser); this checks, without a browser:
#   - the pose columns that --animate adds against the slider-crank's closed
#     form: the crank turns at the driver's 124.8 rad/s about z, so its Euler
#     parameters are (cos(wt/2), 0, 0, sin(wt/2)); the slider sits at
#     x = r cos(wt) + sqrt(L^2 - r^2 sin^2(wt)) (r = 0.1524, L = 0.3048);
#   - the page is self-contained: no script, style or image loaded from
#     anywhere (no src= or href=, no http(s) URL but the XHTML namespace
#     name inside three.js), three.js inlined (its REVISION, the version
#     pinned in web/package.json), and the data embedded: every body, a time
#     per CSV row, the slider's positions equal to the CSV's;
#   - `mbcc animate CSV -m MODEL` writes the same page as `run --animate`;
#     without -m, the bodies of the CSV (and any file name, escaped);
#   - a shape given in the model reaches the page in body axes;
#   - errors: a CSV without pose columns, a missing player, a bad option: exit
#     2, a message that says what to do, and no page (nor a .part) written.
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
B=${B:-build}
case $B in /*) ;; *) B="$root/$B" ;; esac

# 1. run --animate: the pose columns against the closed form
if "$MBCC" run "$root/models/slider_crank.yaml" --animate -o sc.csv --plot none --quiet > run.log 2>&1; then
  [ -s sc.html ] || err "run --animate wrote no sc.html"
  out=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
    { t = $1; w = 124.8 * t; r = 0.1524; L = 0.3048
      e0 = $(c["body.crank.p.e0"]); e3 = $(c["body.crank.p.e3"])
      x = $(c["body.slider.r.x"]); y = $(c["body.slider.r.y"])
      want = r * cos(w) + sqrt(L * L - r * r * sin(w) * sin(w))
      d1 = e0 - cos(w / 2); d2 = e3 - sin(w / 2); d3 = x - want
      if (d1 < 0) d1 = -d1; if (d2 < 0) d2 = -d2; if (d3 < 0) d3 = -d3; if (y < 0) y = -y
      if (d1 > 1e-7 || d2 > 1e-7 || d3 > 1e-7 || y > 1e-9) { print "t=" t ": e0 " e0 " e3 " e3 " x " x " (want " want ")"; exit }
      n++ }
    END { if (n != 501) print "rows " n ", expected 501" }' sc.csv)
  [ -z "$out" ] || err "pose columns against the closed form: $out"
else
  err "mbcc run --animate failed: $(tail -5 run.log)"
fi

# 2. self-contained
if [ -s sc.html ]; then
  grep -Eiq '<(script|link|img|iframe)[^>]*(src|href)=' sc.html && err "the page loads a resource: $(grep -Eio '<(script|link|img|iframe)[^>]*(src|href)=[^>]*' sc.html | head -2)"
  urls=$(grep -Eo 'https?://[^"'"'"' )]*' sc.html | grep -v '^http://www.w3.org/1999/xhtml$' | sort -u)
  [ -z "$urls" ] || err "URLs in the page: $urls"
  rev=$(sed -n 's/.*"three": *"0\.\([0-9]*\)\..*/\1/p' "$root/web/package.json")
  grep -q "REVISION=\"$rev\"\|\"$rev\"" sc.html || err "three.js r$rev is not inlined"
  grep -q 'OrbitControls\|enableDamping' sc.html || err "OrbitControls is not inlined"
  out=$(node -e '
    const fs = require("fs");
    const html = fs.readFileSync("sc.html", "utf8");
    const m = html.match(/<script type="application\/json" id="mbcc-data">([\s\S]*?)<\/script>/);
    if (!m) { console.log("no data in the page"); process.exit(); }
    const d = JSON.parse(m[1]);
    const names = d.bodies.map(b => b.name).join(",");
    if (names !== "crank,rod,slider") console.log("bodies " + names);
    const rows = fs.readFileSync("sc.csv", "utf8").trim().split("\n");
    const head = rows[0].split(","), cx = head.indexOf("body.slider.r.x");
    if (d.time.length !== rows.length - 1) console.log(d.time.length + " times, " + (rows.length - 1) + " rows");
    const s = d.bodies[2];
    for (let i = 1; i < rows.length; i++) {
      const v = Number(rows[i].split(",")[cx]);
      if (Math.abs(s.r[3 * (i - 1)] - v) > 1e-8 * Math.max(1, Math.abs(v))) { console.log("row " + i + ": " + s.r[3 * (i - 1)] + " vs " + v); break; }
    }
    // the crank: its joint points in body axes, 0.0762 m either side of its centre along x
    const p = d.bodies[0].points.map(q => q[0].toFixed(4)).sort().join(",");
    if (p !== "-0.0762,0.0762") console.log("crank points " + JSON.stringify(d.bodies[0].points));
  ' 2>&1)
  [ -z "$out" ] || err "the data in the page: $out"
fi

# 3. mbcc animate on the CSV writes the same page
if "$MBCC" animate sc.csv -m "$root/models/slider_crank.yaml" -o again.html --quiet > an.log 2>&1; then
  cmp -s sc.html again.html || err "mbcc animate and run --animate wrote different pages"
else
  err "mbcc animate failed: $(tail -3 an.log)"
fi
# without the model: the bodies as frames, and a note that says so
if "$MBCC" animate sc.csv -o frames.html > fr.log 2>&1; then
  grep -q 'without the model' fr.log || err "no note about drawing without the model: $(cat fr.log)"
  grep -q '"name":"slider","kind":"rigid","r":' frames.html || err "without the model: body 'slider' missing"
else
  err "mbcc animate without -m failed: $(tail -3 fr.log)"
fi
# a CSV name with characters that mean something in HTML and JSON
cp sc.csv 'we<i>rd"&.csv'
if "$MBCC" animate 'we<i>rd"&.csv' -o weird.html --quiet > we.log 2>&1; then
  grep -q '<title>we&lt;i&gt;rd&quot;&amp;.csv - mbcc animation</title>' weird.html || err "title not escaped: $(grep '<title>' weird.html)"
  out=$(node -e '
    const h = require("fs").readFileSync("weird.html", "utf8");
    const d = JSON.parse(h.match(/id="mbcc-data">([\s\S]*?)<\/script>/)[1]);
    if (d.model !== "we<i>rd\"&.csv") console.log("model " + d.model);' 2>&1)
  [ -z "$out" ] || err "data with an odd CSV name: $out"
else
  err "mbcc animate on an odd CSV name failed: $(tail -3 we.log)"
fi

# 4. a shape, given global at t = 0, stored in body axes (the body turned 90 deg about z)
cat > shaped.yaml <<'EOF'
name: shaped
gravity: [0, -9.81, 0]
bodies:
  arm:
    type: rigid
    mass: 1
    inertia: [0.01, 0.01, 0.01]
    position: [0, -0.5, 0]
    orientation: {axis: [0, 0, 1], angle: 1.5707963267948966}
    shape: {type: cylinder, radius: 0.02, length: 0.8, axis: [0, 1, 0], center: [0, -0.4, 0]}
joints:
  pivot: {type: revolute, bodies: [ground, arm], point: [0, 0, 0], axis: [0, 0, 1]}
simulation: {end_time: 0.05, output_step: 0.01}
EOF
if "$MBCC" run shaped.yaml --path generic --animate -o shaped.csv --plot none --quiet > sh.log 2>&1; then
  out=$(node -e '
    const h = require("fs").readFileSync("shaped.html", "utf8");
    const d = JSON.parse(h.match(/id="mbcc-data">([\s\S]*?)<\/script>/)[1]);
    const s = d.bodies[0].shape, near = (a, b) => a.every((x, i) => Math.abs(x - b[i]) < 1e-9);
    // global y is the body x axis; the centre 0.1 m from the origin along global y
    if (!s || s.type !== "cylinder" || !near(s.axis, [1, 0, 0]) || !near(s.offset, [0.1, 0, 0]))
      console.log(JSON.stringify(s));')
  [ -z "$out" ] || err "shape in body axes: $out"
else
  err "run --animate on a model with a shape failed: $(tail -3 sh.log)"
fi

# 5. errors: exit 2, a message that says what to do, nothing written
"$MBCC" run "$root/models/pendulum.yaml" --path generic -o plain.csv --plot none --quiet > /dev/null 2>&1 || err "plain pendulum run failed"
"$MBCC" animate plain.csv -m "$root/models/pendulum.yaml" -o plain.html > e1.log 2>&1
rc=$?
[ $rc = 2 ] || err "animate on a CSV without pose columns exited $rc, expected 2"
grep -q "error: no column 'body.<name>.r.x' for body .*--animate" e1.log || err "no-pose-columns message: $(cat e1.log)"
MBCC_PLAYER_JS=$tmp/none.js "$MBCC" animate sc.csv -m "$root/models/slider_crank.yaml" -o np.html > e2.log 2>&1
rc=$?
[ $rc = 2 ] || err "animate without a built player exited $rc, expected 2"
grep -q "is not built: run 'make web'" e2.log || err "missing-player message: $(cat e2.log)"
"$MBCC" animate sc.csv --scale -1 > e3.log 2>&1
[ $? = 2 ] || err "--scale -1 accepted"
ls ./*.part plain.html np.html > /dev/null 2>&1 && err "a failed animate left a file: $(ls ./*.part plain.html np.html 2>/dev/null)"

exit $fail
