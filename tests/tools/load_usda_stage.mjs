// Loads a Plume USD stage (value clips over per-frame layers) with tinyusdz, a USD reader nobody on
// Plume wrote, and checks that it describes one animated groom:
//   node load_usda_stage.mjs DIR STAGE.usda FRAMES [PRIMS]   (DIR holds tinyusdz/tinyusdz.{js,wasm})
// tinyusdz parses the stage (layer metadata, the `clips` dictionary, the reference) and composes
// its reference to the first frame layer; it does not evaluate value clips, so this script does
// what a USD stage does with them: it loads every clip layer the stage names (paths relative to the
// stage) with tinyusdz and collects the time samples of `points` of every BasisCurves prim the
// manifest declares. Exits non-zero unless the stage's time range, `active` and `times` agree, every
// clip layer loads and holds its time sample at the time the stage maps to it, the samples cover
// FRAMES time codes, each prim's curve counts and point count stay the same at every sample (as
// Unreal needs), the manifest declares points and extent of the PRIMS BasisCurves prims, and the
// points move over the range.
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

function fail(message) {
  console.error(`load_usda_stage: ${message}`);
  process.exit(1);
}

const [packagesDir, stageFile, expectedFrames, expectedPrims] = process.argv.slice(2);
if (!packagesDir || !stageFile || !expectedFrames) fail('usage: node load_usda_stage.mjs DIR STAGE.usda FRAMES [PRIMS]');
const packageDir = path.join(packagesDir, 'tinyusdz');
globalThis.window = globalThis;
process.type = 'renderer';
const init = (await import(pathToFileURL(path.join(packageDir, 'tinyusdz.js')).href)).default;
const native = await init({ wasmBinary: fs.readFileSync(path.join(packageDir, 'tinyusdz.wasm')) });

function layerText(file) {
  const layer = new native.TinyUSDZLoaderNative();
  if (!layer.loadAsLayerFromBinary(new Uint8Array(fs.readFileSync(file)), file))
    fail(`tinyusdz rejects ${file} as a layer:\n${layer.error()}`);
  return layer.layerToString();
}
const pairs = (text) => [...text.matchAll(/\(([-0-9.e]+), ([-0-9.e]+)\)/g)].map((m) => [Number(m[1]), Number(m[2])]);
const assets = (text) => [...text.matchAll(/@([^@]+)@/g)].map((m) => m[1]);

// 1. The stage, as tinyusdz reads it.
const stageDir = path.dirname(stageFile);
const stage = layerText(stageFile);
for (const key of ['defaultPrim = "Groom"', 'metersPerUnit = ', 'upAxis = ', 'startTimeCode = ', 'endTimeCode = ', 'timeCodesPerSecond = '])
  if (!stage.includes(key)) fail(`the stage has no ${key}`);
if (!/def Xform "Groom"/.test(stage)) fail('the stage has no Xform "Groom"');
const clips = stage.match(/clips = \{\s*dictionary default = \{([\s\S]*?)\n\s*\}\s*\}/);
if (!clips) fail('tinyusdz found no clips dictionary on /Groom');
const field = (name) => {
  const found = clips[1].match(new RegExp(`${name} = (\\[[^\\]]*\\]|@[^@]*@|"[^"]*")`));
  if (!found) fail(`clips: no ${name}`);
  return found[1];
};
const clipAssets = assets(field('asset\\[\\] assetPaths'));
const active = pairs(field('double2\\[\\] active'));
const times = pairs(field('double2\\[\\] times'));
const manifest = assets(field('asset manifestAssetPath'))[0];
if (field('string primPath') !== '"/Groom"') fail('clips: primPath is not "/Groom"');
if (active.length !== clipAssets.length || times.length !== clipAssets.length)
  fail(`clips: ${clipAssets.length} assets, ${active.length} active entries, ${times.length} times`);
const start = Number(stage.match(/startTimeCode = ([-0-9.e]+)/)[1]);
const end = Number(stage.match(/endTimeCode = ([-0-9.e]+)/)[1]);
active.forEach(([time, clip], i) => {
  if (clip !== i) fail(`clips: active[${i}] activates clip ${clip}`);
  if (i > 0 && !(time > active[i - 1][0])) fail('clips: active times do not increase');
  if (times[i][0] !== time || times[i][1] !== time) fail(`clips: times[${i}] does not map ${time} to itself`);
});
if (active[0][0] !== start || active[active.length - 1][0] !== end) fail('clips: active does not span start..endTimeCode');

// tinyusdz composes the stage's reference (the first frame layer: the curves' topology).
const composer = new native.TinyUSDZLoaderNative();
if (!composer.loadAsLayerFromBinary(new Uint8Array(fs.readFileSync(stageFile)), stageFile)) fail(composer.error());
const references = composer.extractReferencesAssetPaths();
const referenced = Array.isArray(references) ? references : [...Array(references.size()).keys()].map((i) => references.get(i));
if (referenced.length !== 1 || referenced[0] !== clipAssets[0]) fail(`the stage references ${referenced}, not the first clip`);
composer.setBaseWorkingPath(stageDir);
composer.setAsset(referenced[0], new Uint8Array(fs.readFileSync(path.join(stageDir, referenced[0]))));
if (!composer.composeReferences()) fail(`tinyusdz cannot compose the stage's reference:\n${composer.error()}`);
const composed = composer.layerToString();
if (!/def BasisCurves "/.test(composed)) fail('the composed stage has no BasisCurves prim');

// 2. The manifest declares the animated attributes of each curves prim.
const manifestText = layerText(path.join(stageDir, manifest));
const prims = [...manifestText.matchAll(/over "([^"]+)"/g)].map((m) => m[1]).filter((name) => name !== 'Groom');
if (expectedPrims !== undefined && prims.length !== Number(expectedPrims))
  fail(`the manifest declares ${prims.length} curves prims, expected ${expectedPrims}`);
// tinyusdz parses the declarations but prints only attributes with values: read them in the text.
const manifestRaw = fs.readFileSync(path.join(stageDir, manifest), 'utf8');
for (const name of prims) {
  const body = manifestRaw.match(new RegExp(`over "${name}"\\s*\\{([^}]*)\\}`));
  if (!body || !/point3f\[\] points\n/.test(body[1]) || !/float3\[\] extent\n/.test(body[1]))
    fail(`the manifest does not declare points and extent of "${name}"`);
}

// 3. Every clip: its time sample, at the time the stage maps to it, for every prim.
const samples = new Map(prims.map((name) => [name, []]));
clipAssets.forEach((asset, i) => {
  const file = path.join(stageDir, asset);
  if (!fs.existsSync(file)) fail(`clip ${asset} does not exist next to the stage`);
  const text = layerText(file);
  const blocks = [...text.matchAll(/def BasisCurves "([^"]+)"/g)];
  for (const name of prims) {
    const at = blocks.findIndex((b) => b[1] === name);
    if (at < 0) fail(`clip ${asset} has no BasisCurves "${name}"`);
    const body = text.slice(blocks[at].index, at + 1 < blocks.length ? blocks[at + 1].index : text.length);
    const sampled = body.match(/point3f\[\] points\.timeSamples = \{\s*([-0-9.e]+): \[([^\]]*)\]/);
    if (!sampled) fail(`clip ${asset}, "${name}": no points time sample`);
    if (Number(sampled[1]) !== times[i][1]) fail(`clip ${asset}: sample at ${sampled[1]}, the stage maps ${times[i][1]}`);
    const counts = body.match(/int\[\] curveVertexCounts = \[([^\]]*)\]/)[1];
    const first = sampled[2].match(/\(([^)]*)\)/)[1];
    samples.get(name).push({ time: Number(sampled[1]), points: (sampled[2].match(/\(/g) ?? []).length, counts, first });
  }
});
let moving = false;
for (const [name, list] of samples) {
  if (list.length !== Number(expectedFrames)) fail(`"${name}": ${list.length} time samples, expected ${expectedFrames}`);
  for (const s of list) {
    if (s.points !== list[0].points || s.counts !== list[0].counts)
      fail(`"${name}": the point count or curve counts change at time ${s.time}`);
    if (s.first !== list[0].first) moving = true;
  }
  console.log(`"${name}": ${list.length} time samples (${list[0].time}..${list[list.length - 1].time}), ${list[0].points} points each`);
}
if (Number(expectedFrames) > 1 && !moving) fail('the points do not move over the range');
console.log(`stage ${path.basename(stageFile)}: ${clipAssets.length} clips over ${start}..${end}, ${prims.length} curves prim(s)`);
