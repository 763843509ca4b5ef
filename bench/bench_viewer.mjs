// The viewer on real grooms: `plume view` of Sintel as the demo writes it, one frame of her 30,000
// strands, and 100,000 strands x 32 points; for each, the time to write the page, its size, and
// the time headless Chromium (software WebGL) takes from navigation to the scene read (parsed,
// decoded, geometry built) and to the first frame drawn (medians of several loads), then to show
// another frame.
//
// node bench/bench_viewer.mjs --plume build/app/plume [--chromium /usr/bin/chromium] [--loads 5]
//   [--screenshot docs/viewer.png]   the demo's page as first drawn (the README's picture)
//   [--cases N]                      the first N pages only (the demo's is the first)
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { cpus, tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { Browser } from '../tests/viewer/browser.mjs';

const args = { chromium: '/usr/bin/chromium', loads: '5', cases: '4' };
for (let i = 2; i + 1 < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
if (!args.plume) throw new Error('usage: node bench/bench_viewer.mjs --plume build/app/plume [--chromium PATH] [--loads N]');
const root = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const sintel = join(root, 'grooms/sintel/sintel.groom.yaml');
const work = mkdtempSync(join(tmpdir(), 'plume-bench-viewer-'));

// Sintel with 32 points per strand: the groom file's own settings but for `strands.points`.
const dense = join(work, 'sintel32.groom.yaml');
writeFileSync(dense, readFileSync(sintel, 'utf8')
  .replace('mesh: sintel.obj', `mesh: ${join(root, 'grooms/sintel/sintel.obj')}`)
  .replace('file: sintel_guides.hair', `file: ${join(root, 'grooms/sintel/sintel_guides.hair')}`)
  .replace(/points: 12/, 'points: 32'));

const median = (values) => [...values].sort((a, b) => a - b)[Math.floor(values.length / 2)];
const cases = [
  { name: 'Sintel demo: frames 1-48:4, 30,000 strands x 12', argv: [sintel, '--frames', '1-48:4'] },
  { name: 'Sintel demo, every frame: 1-48', argv: [sintel, '--frames', '1-48'] },
  { name: 'Sintel, one frame, 30,000 x 12', argv: [sintel, '--frames', '1'] },
  { name: 'Sintel, one frame, 100,000 x 32', argv: [dense, '--frames', '1', '--strands', '100000'] },
];

const browser = await Browser.launch(args.chromium, { width: 1280, height: 800 });
await browser.page('Page.enable');
const rows = [];
try {
  for (const c of cases.slice(0, Number(args.cases))) {
    const page = join(work, 'view.html');
    let started = process.hrtime.bigint();
    execFileSync(args.plume, ['view', ...c.argv, '--out', page], { stdio: ['ignore', 'ignore', 'inherit'] });
    const writeSeconds = Number(process.hrtime.bigint() - started) / 1e9;
    const loads = [], reads = [];
    let frameMs = NaN, shown = 0, total = 0, frames = 0;
    for (let k = 0; k < Number(args.loads); ++k) {
      const url = pathToFileURL(page).href + `?load=${k}`;
      await browser.page('Page.navigate', { url });
      await browser.waitFor(`location.href === ${JSON.stringify(url)} && document.documentElement?.dataset.plumeState === 'ready'`, 300);
      loads.push(await browser.evaluate('plumeViewer.loadMilliseconds'));
      reads.push(await browser.evaluate('plumeViewer.dataMilliseconds'));
      if (k === 0 && c === cases[0] && args.screenshot) {
        await browser.evaluate('new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))');
        writeFileSync(args.screenshot, (await browser.screenshot()).png);
      }
      if (k === 0) {
        ({ shown, total } = await browser.evaluate('({ shown: plumeViewer.strandsShown, total: plumeViewer.strandsTotal })'));
        frames = await browser.evaluate('plumeViewer.frames.length');
        if (frames > 1) {
          frameMs = await browser.evaluate(`new Promise((resolve) => {
            const t0 = performance.now();
            plumeViewer.setFrame(plumeViewer.frames.length - 1);
            requestAnimationFrame(() => requestAnimationFrame(() => resolve(performance.now() - t0)));
          })`);
        }
      }
    }
    rows.push({ name: c.name, frames, shown, total, mb: statSync(page).size / 1e6, writeSeconds, loadMs: median(loads),
      readMs: median(reads),
      loadsMs: loads.map(Math.round).join(' '), frameMs });
    rmSync(page);
  }
} finally {
  await browser.close();
  rmSync(work, { recursive: true, force: true });
}

// Side by side: Blender 3.4 from Debian (built without USD and Alembic) reads the same frame of
// Sintel's 30,000 strands as OBJ line segments, in the background (no drawing): medians of the
// same number of runs. The page's "scene read" is the comparable figure.
let blender = null;
const comparable = rows.find((r) => r.name.startsWith('Sintel, one frame, 30,000'));
try {
  if (!comparable) throw new Error('the one-frame page was not measured');
  execFileSync('blender', ['--version'], { stdio: 'ignore' });
  const dir = mkdtempSync(join(tmpdir(), 'plume-bench-blender-'));
  execFileSync(args.plume, ['regrow', sintel, '--frames', '1', '--out', join(dir, 'hair.####.obj')], { stdio: 'ignore' });
  const script = join(dir, 'import.py');
  writeFileSync(script, [
    'import bpy, sys, time',
    "path = sys.argv[sys.argv.index('--') + 1]",
    'bpy.ops.wm.read_factory_settings(use_empty=True)',
    't = time.perf_counter()',
    'bpy.ops.wm.obj_import(filepath=path)',
    "print('IMPORT', time.perf_counter() - t, len(bpy.data.objects[0].data.edges))",
  ].join('\n'));
  const times = [];
  let edges = 0;
  for (let k = 0; k < Number(args.loads); ++k) {
    const out = execFileSync('blender', ['-b', '--factory-startup', '--python', script, '--', join(dir, 'hair.0001.obj')],
      { encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] });
    const [, seconds, count] = out.match(/IMPORT ([0-9.e-]+) (\d+)/);
    times.push(Number(seconds));
    edges = Number(count);
  }
  rmSync(dir, { recursive: true, force: true });
  blender = { seconds: median(times), runs: times.map((t) => t.toFixed(2)).join(' '), edges };
} catch (error) {
  blender = null;
}

console.log(`bench_viewer: ${cpus().length} cores, headless Chromium with SwiftShader (software WebGL), ${args.loads} loads each`);
console.log('| page | frames | strands shown | size | plume view | scene read (median) | first frame drawn (median) | loads to first frame | next frame shown |');
console.log('|---|---|---|---|---|---|---|---|---|');
for (const r of rows)
  console.log(`| ${r.name} | ${r.frames} | ${r.shown.toLocaleString('en-US')} of ${r.total.toLocaleString('en-US')} | ` +
    `${r.mb.toFixed(1)} MB | ${r.writeSeconds.toFixed(1)} s | ${(r.readMs / 1000).toFixed(2)} s | ${(r.loadMs / 1000).toFixed(2)} s | ${r.loadsMs} ms | ` +
    `${Number.isNaN(r.frameMs) ? '-' : Math.round(r.frameMs) + ' ms'} |`);
if (blender) {
  const page = comparable;
  console.log(`\nBlender 3.4 (Debian) imports the same frame (30,000 strands as ${blender.edges.toLocaleString('en-US')} OBJ line ` +
    `segments, no drawing): ${blender.seconds.toFixed(2)} s (runs ${blender.runs} s); the page reads its scene in ` +
    `${(page.readMs / 1000).toFixed(2)} s (${(page.readMs / 1000 / blender.seconds).toFixed(2)}x Blender's time) and draws it in ` +
    `${(page.loadMs / 1000).toFixed(2)} s with software WebGL`);
} else if (comparable) {
  console.log('\nBlender: not installed (apt-get install blender) or its import failed: no side-by-side figure');
}
