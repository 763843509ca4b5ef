// The page `plume view` writes, opened in a real browser (headless Chromium) and read by an
// independent reader:
// - its data hold the strands `plume regrow` writes for the same frames (to the bit, read back from
//   .hair files by a reader written here);
// - in the browser: no error logged, no request beyond the file itself, the picture has hair where
//   the head is, the strand count shown is the file's, the frame slider, the colour modes, the
//   guides and an orbit drag change the picture, a sampled page says what it shows, and a damaged
//   page reports its error.
//
// node view_test.mjs --plume BIN --groom GROOM --chromium BIN --work DIR [--screenshot OUT.png]
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { Browser } from './browser.mjs';

const args = {};
for (let i = 2; i + 1 < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
for (const required of ['plume', 'groom', 'chromium', 'work'])
  if (!args[required]) throw new Error(`missing --${required}`);
if (!existsSync(args.chromium))
  throw new Error(`no Chromium at ${args.chromium}: install Debian's chromium (./dev.sh test does)`);

let failures = 0;
function check(condition, what) {
  console.log(`${condition ? 'ok  ' : 'FAIL'} ${what}`);
  if (!condition) failures += 1;
}

const work = resolve(args.work);
rmSync(work, { recursive: true, force: true });
mkdirSync(work, { recursive: true });
const plume = (...argv) => execFileSync(args.plume, argv, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });

// ---- The page and its reference strands.
const STRANDS = 1500, FRAMES = [1, 8];
const page = join(work, 'view.html');
plume('view', args.groom, '--frames', '1-8', '--strands', String(STRANDS), '--tolerance', '0.01', '--out', page);
plume('regrow', args.groom, '--frames', '1-8', '--strands', String(STRANDS), '--out', join(work, 'hair.####.hair'), '--no-preview');

/// Cem Yuksel's .hair: 128-byte header, then segments (u16 per hair) when flagged, points (f32 x 3).
function readHair(path) {
  const bytes = readFileSync(path);
  if (bytes.toString('latin1', 0, 4) !== 'HAIR') throw new Error(`${path}: not a .hair file`);
  const hairs = bytes.readUInt32LE(4), points = bytes.readUInt32LE(8), flags = bytes.readUInt32LE(12);
  const defaultSegments = bytes.readUInt32LE(16);
  let at = 128;
  const segments = [];
  for (let h = 0; h < hairs; ++h) segments.push(flags & 1 ? bytes.readUInt16LE(at + 2 * h) : defaultSegments);
  if (flags & 1) at += 2 * hairs;
  const positions = new Float32Array(points * 3);
  for (let i = 0; i < points * 3; ++i) positions[i] = bytes.readFloatLE(at + 4 * i);
  return { hairs, points, segments, positions };
}

/// The manifest and arrays of a page, read without the viewer's code.
function readPage(path) {
  const html = readFileSync(path, 'utf8');
  const manifest = JSON.parse(html.match(/<script type="application\/json" id="plume-scene">([^<]*)<\/script>/)[1]);
  const data = Buffer.from(html.match(/<script type="application\/octet-stream" id="plume-data">([^<]*)<\/script>/)[1], 'base64');
  const types = { f32: Float32Array, f64: Float64Array, u32: Uint32Array, i32: Int32Array, u8: Uint8Array };
  const copy = Uint8Array.from(data);
  const arrays = manifest.buffers.map((b) => new types[b.type](copy.buffer, b.offset, b.length));
  return { html, manifest, arrays };
}

const { html, manifest, arrays } = readPage(page);
check(manifest.strands.total === STRANDS && manifest.strands.shown === STRANDS && !manifest.strands.sample,
  `the page holds all ${STRANDS} strands (total ${manifest.strands.total}, shown ${manifest.strands.shown})`);
check(manifest.frames.join() === '1,2,3,4,5,6,7,8', `the page holds frames 1-8 (${manifest.frames.join()})`);
for (const frame of FRAMES) {
  const hair = readHair(join(work, `hair.${String(frame).padStart(4, '0')}.hair`));
  const index = manifest.frames.indexOf(frame);
  const positions = arrays[manifest.strands.positions[index]];
  const offsets = arrays[manifest.strands.offsets];
  let same = hair.hairs === offsets.length - 1 && positions.length === hair.positions.length;
  for (let s = 0; same && s < hair.hairs; ++s) same = offsets[s + 1] - offsets[s] === hair.segments[s] + 1;
  for (let i = 0; same && i < positions.length; ++i) same = Object.is(positions[i], hair.positions[i]);
  check(same, `frame ${frame}: the page's ${offsets.length - 1} strands are plume regrow's ${hair.hairs}, point for point, to the bit`);
}
check(!/(?:src|href)\s*=\s*["']?(?:https?:)?\/\//i.test(html), 'the page references no network resource');
check(/three\.js authors/i.test(html) && /Permission is hereby granted/.test(html), "the page keeps three.js's licence");

// The checker's counts on the page are plume check's on the same strands (frame 1: the rest pose,
// where the emitter OBJ is the skin). At tolerance 0.01 (about 11 times the default, a thousandth of
// the median segment) the page has pairs to flag: the groom's separation pass parts the strands
// to 5 default tolerances, so at the default there are none (checked below), at 0.01 some remain.
const sintelMesh = join(dirname(resolve(args.groom)), 'sintel.obj');
const checked = plume('check', join(work, 'hair.0001.hair'), '--mesh', sintelMesh, '--tolerance', '0.01');
const inside = Number(checked.match(/points inside the skin \(margin 0\): (\d+)/)[1]);
const [, transversal, touching] = checked.match(/crossing strand pairs \(tolerance 0.01\): (\d+) transversal \(angle above 10 degrees\), (\d+) touching/).map(Number);
const frame1 = manifest.check.frames[0];
check(frame1.points_inside === inside && frame1.transversal_pairs === transversal && frame1.touching_pairs === touching && transversal > 0,
  `the page's frame 1 check is plume check's: ${frame1.points_inside} points inside (${inside}), ` +
  `${frame1.transversal_pairs} transversal (${transversal}) and ${frame1.touching_pairs} touching (${touching}) crossing pairs`);
const atDefault = plume('check', join(work, 'hair.0001.hair'), '--mesh', sintelMesh);
const defaultTransversal = Number(atDefault.match(/crossing strand pairs \(tolerance [0-9.e-]+\): (\d+) transversal/)[1]);
check(defaultTransversal === 0, `at the default tolerance, no transversal pair (${defaultTransversal}): the separation pass is on`);
const flags = arrays[frame1.flags];
check(flags.filter((f) => f & 2).length === frame1.strands_flagged && frame1.transversal_flagged === transversal &&
  frame1.touching_flagged === touching && flags.some((f) => f === 4),
  `every strand of the ${transversal} transversal pairs is flagged (${frame1.strands_flagged} strands), and the touching ones apart`);

/// Colour of strand s in colour mode `mode`, as "r,g,b".
const colorOf = (page, mode, s) => {
  const c = page.arrays[page.manifest.colors.find((entry) => entry.mode === mode).colors];
  return `${c[3 * s]},${c[3 * s + 1]},${c[3 * s + 2]}`;
};
const rootOf = (page, s) => {
  const p = page.arrays[page.manifest.strands.positions[0]], o = page.arrays[page.manifest.strands.offsets];
  return [p[3 * o[s]], p[3 * o[s] + 1], p[3 * o[s] + 2]];
};
const distance = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);

// By guide: without partings the guide that weighs most is the one whose root is nearest the
// strand's root on the rest pose (frame 1), so strands sharing a nearest guide share a colour.
{
  const page = { manifest, arrays };
  const guideOffsets = arrays[manifest.guides.offsets], guidePositions = arrays[manifest.guides.positions[0]];
  const guideRoots = [];
  for (let g = 0; g + 1 < guideOffsets.length; ++g)
    guideRoots.push([0, 1, 2].map((k) => guidePositions[3 * guideOffsets[g] + k]));
  const groups = new Map();
  for (let s = 0; s < manifest.strands.shown; ++s) {
    const root = rootOf(page, s);
    let nearest = 0;
    for (let g = 1; g < guideRoots.length; ++g) if (distance(root, guideRoots[g]) < distance(root, guideRoots[nearest])) nearest = g;
    if (!groups.has(nearest)) groups.set(nearest, []);
    groups.get(nearest).push(colorOf(page, 'guide', s));
  }
  let agreeing = 0;
  const colours = new Set();
  for (const members of groups.values()) {
    const counts = new Map();
    for (const c of members) counts.set(c, (counts.get(c) ?? 0) + 1);
    const [majority, n] = [...counts.entries()].sort((a, b) => b[1] - a[1])[0];
    agreeing += n;
    colours.add(majority);
  }
  // (Binding measures from the guides' roots snapped to the skin, this test from their first points
  // as the file gives them: near-ties may go either way.)
  check(agreeing >= 0.95 * manifest.strands.shown && colours.size >= 0.9 * groups.size,
    `by guide: ${agreeing} of ${manifest.strands.shown} strands take their nearest guide's colour; ${colours.size} colours for ${groups.size} guides`);
}

// By clump (grooms/effects: Poisson clumps of radius 1.2; a stray keeps its clump's colour):
// strands of one colour lie together, within a clump's reach of their centroid.
{
  const groom = join(dirname(resolve(args.groom)), '../effects/effects.groom.yaml');
  const path = join(work, 'effects.html');
  plume('view', groom, '--frames', '1', '--strands', '3000', '--out', path);
  const page = readPage(path);
  const groups = new Map();
  for (let s = 0; s < page.manifest.strands.shown; ++s) {
    const c = colorOf(page, 'clump', s);
    if (!groups.has(c)) groups.set(c, []);
    groups.get(c).push(rootOf(page, s));
  }
  let near = 0, members = 0;
  const stray = '90,90,90';
  for (const [c, roots] of groups) {
    if (c === stray) continue;
    const centroid = [0, 1, 2].map((k) => roots.reduce((sum, r) => sum + r[k], 0) / roots.length);
    members += roots.length;
    near += roots.filter((r) => distance(r, centroid) <= 2 * 1.2).length;
  }
  check(groups.size > 50 && members > 0.99 * page.manifest.strands.shown && near >= 0.95 * members,
    `by clump: ${groups.size} clump colours; ${near} of ${members} strands within two clump radii of their colour's centre`);
}

// By zone and parting side (grooms/sintel_parting: a side parting running front to back near
// x = 3 on top of the head): the two sides take a lighter and a darker shade, one on each side.
{
  const groom = join(dirname(resolve(args.groom)), '../sintel_parting/sintel_parting.groom.yaml');
  const path = join(work, 'parting.html');
  plume('view', groom, '--frames', '1', '--strands', '3000', '--out', path);
  const page = readPage(path);
  const byColor = new Map();
  for (let s = 0; s < page.manifest.strands.shown; ++s) {
    const c = colorOf(page, 'zone', s);
    if (!byColor.has(c)) byColor.set(c, []);
    byColor.get(c).push(rootOf(page, s)[0]);
  }
  const brightness = (c) => c.split(',').map(Number).reduce((a, b) => a + b, 0);
  const shades = [...byColor.keys()].sort((a, b) => brightness(a) - brightness(b));
  const meanX = (c) => byColor.get(c).reduce((a, b) => a + b, 0) / byColor.get(c).length;
  const darker = shades[0], lighter = shades[shades.length - 1];
  check(shades.length === 3 && (meanX(darker) - 3) * (meanX(lighter) - 3) < 0,
    `by parting side: ${shades.length} shades; mean x of the darker side ${meanX(darker).toFixed(2)}, of the lighter ${meanX(lighter).toFixed(2)} (the parting near x = 3)`);
}

// ---- A page of strand files: plume regrow's .hair files of frames 1-8 on the rest skin. Their
// strands are the file's, and at frame 1 (the rest pose) the checker finds what it found above.
const filesPage = join(work, 'files.html');
plume('view', join(work, 'hair.####.hair'), '--frames', '1-8', '--mesh', sintelMesh, '--tolerance', '0.01', '--out', filesPage);
const files = readPage(filesPage);
{
  const hair1 = readHair(join(work, 'hair.0001.hair')), hair8 = readHair(join(work, 'hair.0008.hair'));
  const p1 = files.arrays[files.manifest.strands.positions[0]], p8 = files.arrays[files.manifest.strands.positions[7]];
  let same = p1.length === hair1.positions.length && p8.length === hair8.positions.length;
  for (let i = 0; same && i < p1.length; ++i) same = Object.is(p1[i], hair1.positions[i]) && Object.is(p8[i], hair8.positions[i]);
  check(files.manifest.strands.total === hair1.hairs && same,
    `a page of .hair files holds their ${files.manifest.strands.total} strands, frames 1 and 8 to the bit`);
  const f1 = files.manifest.check.frames[0];
  check(f1.points_inside === inside && f1.transversal_pairs === transversal && f1.touching_pairs === touching,
    `its frame 1 check is plume check's (${f1.points_inside} inside, ${f1.transversal_pairs} transversal and ${f1.touching_pairs} touching pairs)`);
  check(files.manifest.colors.map((c) => c.mode).join() === 'plain,problems' && files.manifest.guides.count === 0,
    'strand files without a groom are coloured plain or by problems, with no guides');
}

// ---- A sampled page: a budget below the strands. The skin and guides move (a rigid turn and
// dynamics): they take their points on every frame, and the strands share what is left.
const sampled = join(work, 'sampled.html');
const BUDGET = 60000, SAMPLED_FRAMES = 4;
plume('view', args.groom, '--frames', `1-${SAMPLED_FRAMES}`, '--strands', String(STRANDS), '--max-points', String(BUDGET), '--out', sampled);
const sampledPage = readPage(sampled);
const s = sampledPage.manifest.strands;
const guidePoints = sampledPage.arrays[sampledPage.manifest.guides.offsets].at(-1);
const pointsPerStrand = sampledPage.arrays[s.offsets][1];
const budgetStrands = Math.floor((BUDGET - SAMPLED_FRAMES * (manifest.skin.vertex_count + guidePoints)) / (SAMPLED_FRAMES * pointsPerStrand));
check(s.sample && s.total === STRANDS && s.shown === budgetStrands && budgetStrands > 0 && budgetStrands < STRANDS,
  `a page over its budget shows a sample: ${s.shown} of ${s.total} strands, the ${budgetStrands} its ${BUDGET} points leave`);

// ---- Feathers: a page of the shipped bird (its curves as the strands, its stems as the guides,
// its vanes as a mesh), read against the vane meshes plume regrow writes for the same frames (OBJ,
// read by a reader written here), and the curves against its .hair files.
const withVanes = join(work, 'bird.html');
{
  const bird = join(dirname(resolve(args.groom)), '../bird/bird.groom.yaml');
  const FEATHERS = 120, BIRD_FRAMES = [1, 24];
  plume('view', bird, '--frames', '1-24:23', '--strands', String(FEATHERS), '--out', withVanes);
  plume('regrow', bird, '--frames', '1-24:23', '--strands', String(FEATHERS), '--out', join(work, 'bird.####.hair'),
    '--vanes', join(work, 'vanes.####.obj'), '--no-preview');
  const readObj = (path) => {
    const v = [], f = [];
    for (const line of readFileSync(path, 'utf8').split('\n')) {
      const w = line.trim().split(/\s+/);
      if (w[0] === 'v') v.push(Number(w[1]), Number(w[2]), Number(w[3]));
      else if (w[0] === 'f') f.push(...w.slice(1).map((x) => Number(x.split('/')[0]) - 1));
    }
    return { v, f };
  };
  const birdPage = readPage(withVanes);
  const vanes = birdPage.manifest.vanes;
  check(vanes && vanes.positions.length === BIRD_FRAMES.length, `the bird's page holds vanes on its ${BIRD_FRAMES.length} frames`);
  BIRD_FRAMES.forEach((frame, index) => {
    const obj = readObj(join(work, `vanes.${String(frame).padStart(4, '0')}.obj`));
    const tris = birdPage.arrays[vanes.triangles], pos = birdPage.arrays[vanes.positions[index]];
    let worst = 0;
    for (let i = 0; i < pos.length && pos.length === obj.v.length; ++i) worst = Math.max(worst, Math.abs(pos[i] - obj.v[i]));
    const sameTriangles = tris.length === obj.f.length && tris.every((t, i) => t === obj.f[i]);
    check(sameTriangles && pos.length === obj.v.length && pos.length > 0 && worst < 1e-4,
      `frame ${frame}: the page's ${tris.length / 3} vane triangles and ${pos.length / 3} vertices are plume regrow's (largest difference ${worst.toExponential(1)})`);
    const hair = readHair(join(work, `bird.${String(frame).padStart(4, '0')}.hair`));
    const curves = birdPage.arrays[birdPage.manifest.strands.positions[index]];
    check(birdPage.manifest.strands.total === hair.hairs && curves.length === hair.positions.length &&
      curves.every((x, i) => Object.is(x, hair.positions[i])),
    `frame ${frame}: the page's ${birdPage.manifest.strands.total} feather curves are plume regrow's, to the bit`);
  });
  check(birdPage.manifest.check.frames.every((f) => f.points_inside === 0),
    "the checker finds no feather point below the bird's skin on the page's frames");
}

// ---- A damaged page: the data cut short.
const damaged = join(work, 'damaged.html');
writeFileSync(damaged, html.replace(/(id="plume-data">)([^<]{1000})[^<]*/, '$1$2'));

// ---- In the browser.
const browser = await Browser.launch(args.chromium, { width: 1000, height: 800 });
const problems = [], requests = [];
browser.onEvent((method, params) => {
  if (method === 'Runtime.consoleAPICalled' && (params.type === 'error' || params.type === 'assert'))
    problems.push(`console.${params.type}: ${params.args.map((a) => a.value ?? a.description).join(' ')}`);
  else if (method === 'Runtime.exceptionThrown')
    problems.push(`exception: ${params.exceptionDetails.exception?.description ?? params.exceptionDetails.text}`);
  else if (method === 'Log.entryAdded' && params.entry.level === 'error') problems.push(`log: ${params.entry.text}`);
  else if (method === 'Network.requestWillBeSent') requests.push(params.request.url);
});
try {
  await browser.page('Runtime.enable');
  await browser.page('Log.enable');
  await browser.page('Network.enable');
  await browser.page('Page.enable');

  const open = async (path) => {
    problems.length = 0;
    requests.length = 0;
    const started = Date.now();
    const url = pathToFileURL(path).href;
    await browser.page('Page.navigate', { url });
    await browser.waitFor(`location.href === ${JSON.stringify(url)} && ` +
      "['ready', 'error'].includes(document.documentElement?.dataset.plumeState)", 120);
    return Date.now() - started;
  };
  const shot = async () => {
    await browser.evaluate('new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))');
    return browser.screenshot();
  };
  // Pixels that differ, within `box` when given, outside the panel (whose controls change as they are used).
  const differing = (a, b, box = null) => {
    let count = 0, total = 0;
    for (let y = 0; y < a.height; ++y)
      for (let x = 0; x < a.width; ++x) {
        if (box && (x < box.left || x > box.right || y < box.top || y > box.bottom)) continue;
        if (x >= panel.left && x <= panel.right && y >= panel.top && y <= panel.bottom) continue;
        ++total;
        const i = 4 * (y * a.width + x);
        if (Math.abs(a.rgba[i] - b.rgba[i]) + Math.abs(a.rgba[i + 1] - b.rgba[i + 1]) + Math.abs(a.rgba[i + 2] - b.rgba[i + 2]) > 24) ++count;
      }
    return { count, total, fraction: count / Math.max(total, 1) };
  };
  const pixels = (image, test, box = null) => {
    let count = 0;
    for (let y = 0; y < image.height; ++y)
      for (let x = 0; x < image.width; ++x) {
        if (box && (x < box.left || x > box.right || y < box.top || y > box.bottom)) continue;
        const i = 4 * (y * image.width + x);
        if (test(image.rgba[i], image.rgba[i + 1], image.rgba[i + 2])) ++count;
      }
    return count;
  };
  const click = async (x, y) => {
    for (const type of ['mousePressed', 'mouseReleased'])
      await browser.page('Input.dispatchMouseEvent', { type, x, y, button: 'left', clickCount: 1 });
  };
  const KEYS = {
    ArrowLeft: { code: 'ArrowLeft', keyCode: 37 },
    g: { code: 'KeyG', keyCode: 71, text: 'g' },
    Enter: { code: 'Enter', keyCode: 13, text: '\r' },
  };
  const press = async (key) => {
    const { code, keyCode, text } = KEYS[key];
    await browser.page('Input.dispatchKeyEvent', { type: text ? 'keyDown' : 'rawKeyDown', key, code, windowsVirtualKeyCode: keyCode, ...(text ? { text } : {}) });
    await browser.page('Input.dispatchKeyEvent', { type: 'keyUp', key, code, windowsVirtualKeyCode: keyCode });
  };
  const rect = (selector) => browser.evaluate(`(() => { const r = document.querySelector('${selector}').getBoundingClientRect(); return { left: r.left, top: r.top, right: r.right, bottom: r.bottom }; })()`);

  const loadMs = await open(page);
  const panel = await rect('#plume-panel');
  const state = await browser.evaluate('document.documentElement.dataset.plumeState');
  check(state === 'ready', `the page is ready (state "${state}"${state === 'error' ? ': ' + (await browser.evaluate('plumeViewer.error')) : ''})`);
  const viewerMs = await browser.evaluate('plumeViewer.loadMilliseconds');
  console.log(`     opened in ${loadMs} ms (page ready ${Math.round(viewerMs)} ms after navigation; ${(statSync(page).size / 1e6).toFixed(1)} MB)`);

  // The strand count the page reports.
  const count = await browser.evaluate("(() => { const e = document.getElementById('strand-count'); return { total: Number(e.dataset.total), shown: Number(e.dataset.shown), text: e.textContent }; })()");
  check(count.total === STRANDS && count.shown === STRANDS && count.text.includes(STRANDS.toLocaleString('en-US')),
    `the page reports the file's ${STRANDS} strands ("${count.text}")`);

  // Hair where the head is: the strands drawn against the same view without them, and their colour.
  const box = await browser.evaluate('plumeViewer.strandScreenBox()');
  const first = await shot();
  if (args.screenshot) writeFileSync(args.screenshot, first.png);
  await click(...Object.values(await rect('label[for="show-strands"]')).slice(0, 2).map((v) => v + 3));
  const bald = await shot();
  const hairDiff = differing(first, bald, box);
  check(hairDiff.fraction > 0.05, `hair is drawn where the head is: ${hairDiff.count} of ${hairDiff.total} pixels of the strands' box change without them`);
  const hairColored = pixels(first, (r, g, b) => r > g && g > b && r - b > 30 && r + g + b < 420, box);
  check(hairColored > 0.03 * hairDiff.total, `hair-coloured pixels in the strands' box: ${hairColored}`);
  check(pixels(first, (r, g, b) => Math.max(r, g, b) - Math.min(r, g, b) > 12) > 0.05 * first.width * first.height, 'the picture is not blank');
  await click(...Object.values(await rect('label[for="show-strands"]')).slice(0, 2).map((v) => v + 3));
  check(differing(first, await shot()).count === 0, 'showing the strands again gives the same picture');

  // The frame slider: a click at its right end goes to the last frame and changes the picture.
  const slider = await rect('#frame');
  await click(slider.right - 3, (slider.top + slider.bottom) / 2);
  const frameIndex = await browser.evaluate('plumeViewer.frameIndex');
  const label = await browser.evaluate("document.getElementById('frame-label').textContent");
  check(frameIndex === 7 && label.startsWith('frame 8'), `the slider's end is the last frame (index ${frameIndex}, "${label}")`);
  const last = await shot();
  const frameDiff = differing(first, last);
  check(frameDiff.fraction > 0.003, `the slider changes the picture (${frameDiff.count} pixels differ between frames 1 and 8)`);
  await press('ArrowLeft');
  check((await browser.evaluate('plumeViewer.frameIndex')) === 6, 'the left arrow steps back one frame');
  await click(slider.left + 3, (slider.top + slider.bottom) / 2);
  check(differing(first, await shot()).count === 0, 'back at frame 1, the picture is frame 1 again');

  // Guides over the strands: bright cyan pixels appear with "g".
  const cyan = (r, g, b) => b > 170 && g > 140 && r < 120;
  const cyanBefore = pixels(first, cyan);
  await press('g');
  const withGuides = await shot();
  const cyanAfter = pixels(withGuides, cyan);
  check(cyanAfter > cyanBefore + 500, `the guides are drawn over the strands (${cyanBefore} -> ${cyanAfter} guide-coloured pixels)`);
  await press('g');

  // Colour modes: by guide, and the checker's problems (the page was written with --tolerance 0.01).
  const setMode = async (mode) => {
    await browser.evaluate(`(() => { const s = document.getElementById('color-mode'); s.value = '${mode}'; s.dispatchEvent(new Event('change')); })()`);
    return shot();
  };
  const byGuide = await setMode('guide');
  check(differing(first, byGuide, box).fraction > 0.05, 'colouring by guide changes the picture');
  const flagged = manifest.check.frames[0].strands_flagged;
  const byProblems = await setMode('problems');
  const orange = pixels(byProblems, (r, g, b) => r > 200 && g > 100 && g < 200 && b < 80, box);
  check(flagged > 0 && orange > 200, `the ${flagged} strands the checker flags at frame 1 are drawn in the crossing colour (${orange} pixels)`);
  const summary = await browser.evaluate("document.getElementById('check-summary').textContent");
  check(summary.includes(`${transversal.toLocaleString('en-US')} transversal, ${touching.toLocaleString('en-US')} touching`),
    `the check summary states the checker's counts ("${summary}")`);
  await setMode('plain');

  // A strand the checker flags, found by its id as plume check prints it: drawn in white, and the
  // panel says what the checker found on it. An id the page does not hold is said so.
  const flaggedIndex = arrays[frame1.flags].findIndex((f) => (f & 2) !== 0);
  const flaggedId = arrays[manifest.strands.ids][flaggedIndex];
  // (The skin is hidden meanwhile: the strand may lie behind the head.)
  const white = (image) => pixels(image, (r, g, b) => r > 235 && g > 235 && b > 235, { left: panel.right + 1, top: 0, right: image.width, bottom: image.height });
  const skinBox = await rect('label[for="show-skin"]');
  await click(skinBox.left + 3, skinBox.top + 3);
  const whiteBefore = white(await shot());
  const findBox = await rect('#find-strand');
  await click(findBox.left + 5, (findBox.top + findBox.bottom) / 2);
  await browser.page('Input.insertText', { text: String(flaggedId) });
  await press('Enter');
  const whiteAfter = white(await shot());
  await click(skinBox.left + 3, skinBox.top + 3);
  const info = await browser.evaluate("document.getElementById('strand-info').textContent");
  check((await browser.evaluate('plumeViewer.selectedStrand')) === flaggedId && info.includes('crossing another strand') &&
    whiteAfter > whiteBefore + 20,
    `finding strand ${flaggedId} by id draws it in white (${whiteBefore} -> ${whiteAfter} white pixels): "${info}"`);
  await browser.evaluate("document.getElementById('find-strand').value = ''");
  await click(findBox.left + 5, (findBox.top + findBox.bottom) / 2);
  await browser.page('Input.insertText', { text: '987654321' });
  await press('Enter');
  const missing = await browser.evaluate("document.getElementById('strand-info').textContent");
  check(missing.includes('987654321 is not on this page') && (await browser.evaluate('plumeViewer.selectedStrand')) === null,
    `an id the page does not hold is said so ("${missing}")`);

  // A click on hair picks a strand; a click on the background picks none.
  let best = null;
  for (let y = Math.ceil(box.top); y < box.bottom && !best; y += 3)
    for (let x = Math.ceil(box.left); x < box.right; x += 3) {
      const i = 4 * (y * first.width + x);
      const lit = (p) => p.rgba[i] + p.rgba[i + 1] + p.rgba[i + 2];
      if (x > panel.right + 5 && Math.abs(lit(first) - lit(bald)) > 60 && first.rgba[i] > first.rgba[i + 2] + 30) {
        best = { x, y };
        break;
      }
    }
  await click(best.x, best.y);
  const picked = await browser.evaluate('plumeViewer.selectedStrand');
  check(picked !== null && (await browser.evaluate("document.getElementById('strand-info').textContent")).startsWith(`Strand ${picked}`),
    `a click on hair at (${best.x}, ${best.y}) picks strand ${picked}`);
  await click(first.width - 10, first.height - 10);
  check((await browser.evaluate('plumeViewer.selectedStrand')) === null, 'a click on the background picks none');

  // Orbit: a drag turns the head.
  const centre = { x: (box.left + box.right) / 2, y: (box.top + box.bottom) / 2 };
  await browser.page('Input.dispatchMouseEvent', { type: 'mousePressed', x: centre.x, y: centre.y, button: 'left', clickCount: 1 });
  for (let k = 1; k <= 10; ++k)
    await browser.page('Input.dispatchMouseEvent', { type: 'mouseMoved', x: centre.x + 20 * k, y: centre.y, button: 'left', buttons: 1 });
  await browser.page('Input.dispatchMouseEvent', { type: 'mouseReleased', x: centre.x + 200, y: centre.y, button: 'left', clickCount: 1 });
  check(differing(first, await shot()).fraction > 0.02, 'dragging turns the view');

  check(problems.length === 0, `no error logged by the page${problems.length ? ': ' + problems.join('; ') : ''}`);
  const remote = requests.filter((url) => !url.startsWith('file:') && !url.startsWith('data:'));
  check(remote.length === 0, `no request beyond the file and its data${remote.length ? ': ' + remote.join(' ') : ''}`);

  // The page of strand files reports the files' strand count.
  await open(filesPage);
  const filesCount = await browser.evaluate("Number(document.getElementById('strand-count').dataset.total)");
  check(filesCount === STRANDS && problems.length === 0,
    `a page of .hair files reports their ${filesCount} strands, with no error${problems.length ? ': ' + problems.join('; ') : ''}`);

  // Vanes: drawn, toggled by their box.
  await open(withVanes);
  const vanesBox = await browser.evaluate("!!document.getElementById('show-vanes')");
  const withThem = await shot();
  await click(...Object.values(await rect('label[for="show-vanes"]')).slice(0, 2).map((v) => v + 3));
  const withoutThem = await shot();
  const vaneDiff = differing(withThem, withoutThem);
  check(vanesBox && vaneDiff.count > 1000 && problems.length === 0,
    `a page with vanes draws them (${vaneDiff.count} pixels change when they are hidden)${problems.length ? ': ' + problems.join('; ') : ''}`);

  // The sampled page says what it shows.
  await open(sampled);
  const sampledText = await browser.evaluate("document.getElementById('strand-count').textContent");
  check(sampledText.startsWith(`${s.shown.toLocaleString('en-US')} of ${STRANDS.toLocaleString('en-US')} strands shown`),
    `a sampled page states its sample ("${sampledText}")`);
  check(problems.length === 0, `no error logged by the sampled page${problems.length ? ': ' + problems.join('; ') : ''}`);

  // A damaged page reports its error (and the harness sees it).
  await open(damaged);
  const damagedState = await browser.evaluate('document.documentElement.dataset.plumeState');
  const message = await browser.evaluate("document.getElementById('plume-error')?.textContent ?? ''");
  check(damagedState === 'error' && message.includes('buffer') && problems.length > 0,
    `a damaged page shows its error ("${message}") and logs it (${problems.length} logged)`);
} finally {
  await browser.close();
}

if (failures) {
  console.log(`${failures} check(s) failed`);
  process.exit(1);
}
console.log('all checks passed');
