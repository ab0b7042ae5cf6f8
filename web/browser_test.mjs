// browser_test.mjs: an animation page of `mbcc animate` in headless Chromium
// (Debian's chromium, driven by puppeteer-core; no network).
//   node browser_test.mjs SPEC.json
// SPEC: {html, screenshot, bodies: [names], frame_for_shot, joints: [...],
//        deflections: [...]}; see tests/test_browser.sh, which writes it.
// Checks, each against something the player does not compute itself:
//   - the page loads with no console error, no page error, and no request
//     other than the page itself (three.js and the data are inlined);
//   - every body of the model is in the scene (window.mbccScene);
//   - Play advances the frame, Pause stops it, the slider sets it;
//   - joints: a flexible body's node drawn at r + A (x + X w) coincides with
//     the point of the other body that a joint holds it to (the constraint
//     the simulation enforced), at several frames;
//   - deflections: a node's drawn deflection from a chord, in body axes,
//     equals the simulator's own deflection output column;
// then it takes a screenshot.  Exit 0 = pass; prints what failed.
import fs from 'node:fs';
import puppeteer from 'puppeteer-core';

const spec = JSON.parse(fs.readFileSync(process.argv[2], 'utf8'));
const failures = [];
const fail = msg => { failures.push(msg); console.log('FAIL: ' + msg); };
const executablePath = process.env.CHROMIUM || '/usr/bin/chromium';

const browser = await puppeteer.launch({
  executablePath,
  headless: true,
  // WebGL without a GPU: SwiftShader, the software renderer Chromium ships
  // and no background connections: the machine has no network but package registries
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
         '--disable-gpu-sandbox', '--no-first-run', '--disable-extensions', '--disable-quic',
         '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1000, height: 600 });
  const pageUrl = 'file://' + fs.realpathSync(spec.html);
  page.on('console', m => { if (m.type() === 'error') fail('console error: ' + m.text()); });
  page.on('pageerror', e => fail('page error: ' + e.message));
  await page.setRequestInterception(true);
  page.on('request', r => {
    const u = r.url();
    if (u === pageUrl || u.startsWith('data:') || u.startsWith('blob:')) r.continue();
    else { fail('the page requested ' + u); r.abort(); }
  });
  await page.goto(pageUrl, { waitUntil: 'load' });
  await page.waitForFunction(() => window.mbccScene && window.mbccScene.ready, { timeout: 15000 });
  const info = await page.evaluate(() => ({ bodies: mbccScene.bodies, names: mbccScene.bodyNames,
                                            frames: mbccScene.frames, meshes: mbccScene.meshes }));
  if (info.bodies !== spec.bodies.length) fail(`${info.bodies} bodies in the scene, expected ${spec.bodies.length}`);
  for (const n of spec.bodies) if (!info.names.includes(n)) fail(`body '${n}' is not in the scene`);
  info.meshes.forEach((k, i) => { if (!(k > 0)) fail(`body '${info.names[i]}' has nothing drawn`); });
  if (info.frames !== spec.frames) fail(`${info.frames} frames, expected ${spec.frames} (the CSV rows)`);

  // play: the frame advances; pause: it stays
  const f0 = await page.evaluate(() => mbccScene.frame);
  await page.click('#play');
  await page.waitForFunction(f => mbccScene.frame !== f, { timeout: 5000 }, f0).catch(() => {});
  const f1 = await page.evaluate(() => mbccScene.frame);
  if (f1 === f0) fail(`the frame did not advance while playing (frame ${f0})`);
  await page.click('#play');
  const f2 = await page.evaluate(() => mbccScene.frame);
  await new Promise(r => setTimeout(r, 300));
  const f3 = await page.evaluate(() => ({ f: mbccScene.frame, playing: mbccScene.playing }));
  if (f3.playing || f3.f !== f2) fail(`the frame moved after pause (${f2} -> ${f3.f})`);
  // the slider sets the frame
  await page.evaluate(n => { const s = document.getElementById('time'); s.value = String(n); s.dispatchEvent(new Event('input')); }, 7);
  if ((await page.evaluate(() => mbccScene.frame)) !== 7) fail('the time slider does not set the frame');

  const data = await page.evaluate(() => JSON.parse(document.getElementById('mbcc-data').textContent));
  const body = name => data.bodies.find(b => b.name === name);
  const rotate = (p, f, v) => { // A(p) v with Euler parameters p at frame f
    const e0 = p[4 * f], e1 = p[4 * f + 1], e2 = p[4 * f + 2], e3 = p[4 * f + 3];
    const A = [2 * (e0 * e0 + e1 * e1) - 1, 2 * (e1 * e2 - e0 * e3), 2 * (e1 * e3 + e0 * e2),
               2 * (e1 * e2 + e0 * e3), 2 * (e0 * e0 + e2 * e2) - 1, 2 * (e2 * e3 - e0 * e1),
               2 * (e1 * e3 - e0 * e2), 2 * (e2 * e3 + e0 * e1), 2 * (e0 * e0 + e3 * e3) - 1];
    return [0, 1, 2].map(i => A[3 * i] * v[0] + A[3 * i + 1] * v[1] + A[3 * i + 2] * v[2]);
  };
  const frames = [1, Math.floor(info.frames / 3), Math.floor(2 * info.frames / 3), info.frames - 1];
  for (const j of spec.joints || []) {
    // node j.node of flexible body j.flexible against the point j.point (body axes) of body j.other
    let worst = 0, moved = 0;
    for (const f of frames) {
      const x = await page.evaluate((n, f) => { mbccScene.setFrame(f); return mbccScene.nodes(n); }, j.flexible, f);
      const o = body(j.other), fb = body(j.flexible);
      const s = rotate(o.p, f, j.point), want = [0, 1, 2].map(i => o.r[3 * f + i] + s[i]);
      worst = Math.max(worst, Math.hypot(...[0, 1, 2].map(i => x[j.node][i] - want[i])));
      // how far the deformation moved the node: what the check must resolve
      const k = j.node, und = rotate(fb.p, f, fb.nodes.slice(3 * k, 3 * k + 3));
      const rigid = [0, 1, 2].map(i => fb.r[3 * f + i] + und[i]);
      moved = Math.max(moved, Math.hypot(...[0, 1, 2].map(i => x[k][i] - rigid[i])));
    }
    console.log(`joint ${j.name}: node ${j.node} of ${j.flexible} vs ${j.other}: ${worst.toExponential(2)} m ` +
                `(the deformation moves the node ${moved.toExponential(2)} m)`);
    if (!(worst < j.tolerance)) fail(`joint ${j.name}: the drawn node is ${worst} m from the joint point`);
    if (!(moved > 100 * j.tolerance)) fail(`joint ${j.name}: the deformation (${moved} m) is too small to check`);
  }
  for (const d of spec.deflections || []) {
    // deflection of node d.node from the chord of nodes d.chord, body axes, component d.component, times d.scale
    let worst = 0, peak = 0;
    for (let i = 0; i < d.frames.length; i++) {
      const f = d.frames[i];
      const x = await page.evaluate((n, f) => { mbccScene.setFrame(f); return mbccScene.nodes(n); }, d.body, f);
      const b = body(d.body);
      // back to body axes: A^T (x - r)
      const e = [b.p[4 * f], -b.p[4 * f + 1], -b.p[4 * f + 2], -b.p[4 * f + 3]];
      const local = k => rotate(e, 0, [0, 1, 2].map(c => x[k][c] - b.r[3 * f + c]));
      const u = k => { const l = local(k); return [0, 1, 2].map(c => l[c] - b.nodes[3 * k + c]); };
      const [a, c] = d.chord, xa = b.nodes.slice(3 * a, 3 * a + 3), xc = b.nodes.slice(3 * c, 3 * c + 3);
      const xk = b.nodes.slice(3 * d.node, 3 * d.node + 3);
      const L2 = [0, 1, 2].reduce((s, m) => s + (xc[m] - xa[m]) ** 2, 0);
      const t = [0, 1, 2].reduce((s, m) => s + (xk[m] - xa[m]) * (xc[m] - xa[m]), 0) / L2;
      const ua = u(a), uc = u(c), uk = u(d.node);
      const got = d.scale * (uk[d.component] - ((1 - t) * ua[d.component] + t * uc[d.component]));
      worst = Math.max(worst, Math.abs(got - d.values[i]));
      peak = Math.max(peak, Math.abs(d.values[i]));
    }
    console.log(`deflection ${d.name}: drawn vs simulated, worst difference ${worst.toExponential(2)} (peak ${peak.toExponential(2)})`);
    if (!(worst < 1e-4 * peak)) fail(`deflection ${d.name}: the drawn deflection differs by ${worst} (peak ${peak})`);
  }

  await page.evaluate(f => mbccScene.setFrame(f), spec.frame_for_shot || 0);
  if (spec.scale !== undefined)
    await page.evaluate(s => { const e = document.getElementById('scale'); e.value = String(s); e.dispatchEvent(new Event('input')); }, spec.scale);
  await page.evaluate(f => mbccScene.setFrame(f), spec.frame_for_shot || 0);
  if (spec.screenshot) await page.screenshot({ path: spec.screenshot });
  // the canvas is not blank: WebGL drew something other than the background
  const drawn = await page.evaluate(() => {
    const c = document.querySelector('#view canvas'), g = document.createElement('canvas');
    g.width = c.width; g.height = c.height;
    const ctx = g.getContext('2d'); ctx.drawImage(c, 0, 0);
    const px = ctx.getImageData(0, 0, g.width, g.height).data;
    let other = 0;
    for (let i = 0; i < px.length; i += 4) if (Math.abs(px[i] - 0xf4) + Math.abs(px[i + 1] - 0xf5) + Math.abs(px[i + 2] - 0xf7) > 30) other++;
    return other / (px.length / 4);
  });
  if (!(drawn > 0.002)) fail(`the canvas is blank (${(100 * drawn).toFixed(3)}% drawn)`);
} finally {
  await browser.close();
}
console.log(failures.length ? `${failures.length} failure(s)` : 'browser test: ok');
process.exit(failures.length ? 1 : 0);
