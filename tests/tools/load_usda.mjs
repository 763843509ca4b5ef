// Loads a .usda with tinyusdz (a USD reader nobody on Plume wrote) and checks what it found.
//   node load_usda.mjs DIR FILE.usda [CURVES POINTS [PRIMS]]   (DIR holds tinyusdz/tinyusdz.{js,wasm})
// Exits non-zero when tinyusdz rejects the file (syntax, types, BasisCurves schema), when the
// curves it parsed are inconsistent (counts vs points, widths, primvars), when the per-curve
// `int[] primvars:groom_group_id` (hair group, as Unreal reads it) or `int64[] primvars:plume_id`
// (stable strand ids) is missing, when a per-curve primvar other than plume_id is not named
// `groom_*` (Unreal's importer drops it), or when the numbers of curves and points differ from CURVES and
// POINTS (totals over the BasisCurves prims, one per hair group), or the number of BasisCurves
// prims from PRIMS.
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

function fail(message) {
  console.error(`load_usda: ${message}`);
  process.exit(1);
}

const [packagesDir, file, expectedCurves, expectedPoints, expectedGroups] = process.argv.slice(2);
if (!packagesDir || !file) fail('usage: node load_usda.mjs DIR FILE.usda [CURVES POINTS]');
const packageDir = path.join(packagesDir, 'tinyusdz');
if (!fs.existsSync(path.join(packageDir, 'tinyusdz.wasm')))
  fail(`no tinyusdz.wasm in ${packageDir} (see tests/third_party/tinyusdz/README.md)`);

// tinyusdz ships a browser build: make it take the web path under Node and hand it the wasm bytes.
globalThis.window = globalThis;
process.type = 'renderer';
const init = (await import(pathToFileURL(path.join(packageDir, 'tinyusdz.js')).href)).default;
const native = await init({ wasmBinary: fs.readFileSync(path.join(packageDir, 'tinyusdz.wasm')) });
const bytes = new Uint8Array(fs.readFileSync(file));

// 1. As a stage: parses the text and rebuilds every prim through its typed schema (BasisCurves).
const stage = new native.TinyUSDZLoaderNative();
if (!stage.loadFromBinary(bytes, file)) fail(`tinyusdz rejects ${file} as a stage:\n${stage.error()}`);
const paths = [];
const walk = (node) => {
  paths.push(node.absPath);
  for (const child of node.children ?? []) walk(child);
};
for (let i = 0; i < stage.numRootNodes(); ++i) walk(stage.getRootNode(i));
console.log(`prims: ${paths.join(' ')}`);

// 2. As a layer, printed back by tinyusdz: the values it parsed, attribute by attribute.
const layer = new native.TinyUSDZLoaderNative();
if (!layer.loadAsLayerFromBinary(bytes, file)) fail(`tinyusdz rejects ${file} as a layer:\n${layer.error()}`);
const dump = layer.layerToString();

const curvesBlocks = [...dump.matchAll(/def BasisCurves "([^"]+)"/g)];
if (curvesBlocks.length < 1) fail('expected a BasisCurves prim, tinyusdz found none');
if (!/defaultPrim = "Groom"/.test(dump)) fail('tinyusdz found no defaultPrim = "Groom"');
if (!/def Xform "Groom"/.test(dump)) fail('tinyusdz found no Xform "Groom"');
const groupIds = [];
let curveTotal = 0, pointTotal = 0;
// Each BasisCurves prim (one per hair group) is checked on its own text.
for (let b = 0; b < curvesBlocks.length; ++b) {
  const text = dump.slice(curvesBlocks[b].index, b + 1 < curvesBlocks.length ? curvesBlocks[b + 1].index : dump.length);
  // The array on the line of `name` (a default value, or the first time sample on the next line).
  function arrayOf(name) {
    const escaped = name.replace(/[.:[\]]/g, '\\$&');
    const plain = text.match(new RegExp(`\\s${escaped} = \\[([^\\]]*)\\]`));
    if (plain) return plain[1];
    const sampled = text.match(new RegExp(`\\s${escaped}\\.timeSamples = \\{\\s*[-0-9.e]+: \\[([^\\]]*)\\]`));
    return sampled ? sampled[1] : null;
  }
  const numbers = (text) => (text.trim() === '' ? [] : text.split(',').map((s) => Number(s.replace(/[()]/g, ''))));
  const tuples = (text) => (text.match(/\(/g) ?? []).length;

  const countsText = arrayOf('int[] curveVertexCounts');
  const pointsText = arrayOf('point3f[] points');
  if (countsText === null) fail('tinyusdz found no int[] curveVertexCounts');
  if (pointsText === null) fail('tinyusdz found no point3f[] points');
  const counts = numbers(countsText);
  const pointNum = tuples(pointsText);
  if (counts.some((c) => !Number.isInteger(c) || c < 2)) fail('curveVertexCounts: expected integers >= 2 (linear curves)');
  const countSum = counts.reduce((a, b) => a + b, 0);
  if (countSum !== pointNum) fail(`curveVertexCounts add up to ${countSum}, tinyusdz read ${pointNum} points`);
  if (!/uniform token type = "linear"/.test(text)) fail('expected uniform token type = "linear"');

  const widthsText = arrayOf('float[] widths');
  if (widthsText !== null) {
    const widthNum = numbers(widthsText).length;
    if (![1, counts.length, pointNum].includes(widthNum))
      fail(`widths: ${widthNum} values, expected 1, ${counts.length} or ${pointNum}`);
  }
  for (const found of text.matchAll(/\s(\S+) primvars:([A-Za-z0-9_]+)/g))
    if (found[2] !== 'plume_id' && !found[2].startsWith('groom_')) fail(`primvars:${found[2]}: Unreal reads only groom_* primvars`);
  for (const primvar of ['int[] primvars:groom_group_id', 'int64[] primvars:plume_id', 'texCoord2f[] primvars:groom_root_uv']) {
    const text = arrayOf(primvar);
    if (text === null) {
      if (primvar.startsWith('texCoord2f')) continue;
      fail(`tinyusdz found no ${primvar}`);
    }
    const found = primvar.startsWith('texCoord2f') ? tuples(text) : numbers(text).length;
    if (found !== counts.length) fail(`${primvar}: ${found} values, expected one per curve (${counts.length})`);
  }
  // tinyusdz 0.9.0-rc10 type-checks int64[] (it rejects 2^63 and 1.5) and counts its values right, but
  // prints wrong values for some int64 arrays (e.g. [100, 101, ..., 111] as all 1s), so only the count
  // of plume_id is checked here; Plume's own round trip (tests/io) checks the 64-bit values exactly.
  for (const id of numbers(arrayOf('int[] primvars:groom_group_id'))) groupIds.push(id);
  console.log(`BasisCurves "${curvesBlocks[b][1]}": ${counts.length} curves, ${pointNum} points`);
  curveTotal += counts.length;
  pointTotal += pointNum;
}
console.log(`primvars: ${curveTotal} plume_id, ${new Set(groupIds).size} groom_group_id group(s)`);

if (expectedCurves !== undefined && Number(expectedCurves) !== curveTotal)
  fail(`expected ${expectedCurves} curves, tinyusdz found ${curveTotal}`);
if (expectedPoints !== undefined && Number(expectedPoints) !== pointTotal)
  fail(`expected ${expectedPoints} points, tinyusdz found ${pointTotal}`);
if (expectedGroups !== undefined && Number(expectedGroups) !== curvesBlocks.length)
  fail(`expected ${expectedGroups} BasisCurves prims (hair groups), tinyusdz found ${curvesBlocks.length}`);
