// Loads feather files Plume wrote with tinyusdz (a USD reader nobody on Plume wrote):
//   node load_feathers_usda.mjs DIR CURVES.usda VANES.usda   (DIR holds tinyusdz/tinyusdz.{js,wasm})
// Exits non-zero when tinyusdz rejects either file, or when what it parsed is inconsistent: the
// curves' counts and points, vertex widths and texture coordinates (st, st_vane), one feather_id,
// feather_part, feather_template, groom_group_id and plume_id per curve; the vanes' triangles, indices within
// the points, vertex st and st_barb, one feather_id and feather_template per face.
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

function fail(message) {
  console.error(`load_feathers_usda: ${message}`);
  process.exit(1);
}

const [packagesDir, curvesFile, vanesFile] = process.argv.slice(2);
if (!packagesDir || !curvesFile || !vanesFile) fail('usage: node load_feathers_usda.mjs DIR CURVES.usda VANES.usda');
const packageDir = path.join(packagesDir, 'tinyusdz');
globalThis.window = globalThis;
process.type = 'renderer';
const init = (await import(pathToFileURL(path.join(packageDir, 'tinyusdz.js')).href)).default;
const native = await init({ wasmBinary: fs.readFileSync(path.join(packageDir, 'tinyusdz.wasm')) });

function load(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const stage = new native.TinyUSDZLoaderNative();
  if (!stage.loadFromBinary(bytes, file)) fail(`tinyusdz rejects ${file} as a stage:\n${stage.error()}`);
  const layer = new native.TinyUSDZLoaderNative();
  if (!layer.loadAsLayerFromBinary(bytes, file)) fail(`tinyusdz rejects ${file} as a layer:\n${layer.error()}`);
  return layer.layerToString();
}
function arrayOf(dump, name) {
  const escaped = name.replace(/[.:[\]]/g, '\\$&');
  const plain = dump.match(new RegExp(`\\s${escaped} = \\[([^\\]]*)\\]`));
  if (plain) return plain[1];
  const sampled = dump.match(new RegExp(`\\s${escaped}\\.timeSamples = \\{\\s*[-0-9.e]+: \\[([^\\]]*)\\]`));
  if (sampled) return sampled[1];
  fail(`tinyusdz found no ${name}`);
}
const numbers = (text) => (text.trim() === '' ? [] : text.split(',').map((s) => Number(s.replace(/[()]/g, ''))));
const tuples = (text) => (text.match(/\(/g) ?? []).length;

// The curves.
const curves = load(curvesFile);
if (!/def BasisCurves "feathers"/.test(curves)) fail('expected a BasisCurves prim "feathers"');
const counts = numbers(arrayOf(curves, 'int[] curveVertexCounts'));
const pointNum = tuples(arrayOf(curves, 'point3f[] points'));
if (counts.reduce((a, b) => a + b, 0) !== pointNum) fail('curveVertexCounts do not add up to the points');
if (numbers(arrayOf(curves, 'float[] widths')).length !== pointNum) fail('widths: expected one per point');
for (const st of ['texCoord2f[] primvars:st', 'texCoord2f[] primvars:st_vane'])
  if (tuples(arrayOf(curves, st)) !== pointNum) fail(`${st}: expected one per point`);
for (const primvar of ['int64[] primvars:feather_id', 'int64[] primvars:plume_id', 'int[] primvars:feather_part',
                       'int[] primvars:feather_template', 'int[] primvars:groom_group_id'])
  if (numbers(arrayOf(curves, primvar)).length !== counts.length) fail(`${primvar}: expected one per curve`);
const parts = new Set(numbers(arrayOf(curves, 'int[] primvars:feather_part')));
if (![...parts].every((p) => p >= 0 && p <= 5)) fail('feather_part: expected values 0 to 5');
console.log(`BasisCurves "feathers": ${counts.length} curves, ${pointNum} points, parts ${[...parts].sort().join(' ')}`);

// The vanes.
const vanes = load(vanesFile);
if (!/def Mesh "vanes"/.test(vanes)) fail('expected a Mesh prim "vanes"');
const faceCounts = numbers(arrayOf(vanes, 'int[] faceVertexCounts'));
const indices = numbers(arrayOf(vanes, 'int[] faceVertexIndices'));
const vertexNum = tuples(arrayOf(vanes, 'point3f[] points'));
if (!faceCounts.every((c) => c === 3)) fail('faceVertexCounts: expected triangles');
if (indices.length !== 3 * faceCounts.length) fail('faceVertexIndices: expected 3 per face');
if (!indices.every((i) => Number.isInteger(i) && i >= 0 && i < vertexNum)) fail('faceVertexIndices: out of range');
for (const st of ['texCoord2f[] primvars:st', 'texCoord2f[] primvars:st_barb'])
  if (tuples(arrayOf(vanes, st)) !== vertexNum) fail(`${st}: expected one per vertex`);
for (const primvar of ['int64[] primvars:feather_id', 'int[] primvars:feather_template'])
  if (numbers(arrayOf(vanes, primvar)).length !== faceCounts.length) fail(`${primvar}: expected one per face`);
console.log(`Mesh "vanes": ${faceCounts.length} triangles, ${vertexNum} vertices`);
