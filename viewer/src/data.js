// Reads the scene a page carries: the manifest (JSON, <script id="plume-scene">) and its arrays
// (little-endian binary, base64 in <script id="plume-data">). Layout: docs/viewer.md.

const ARRAY_TYPES = {
  f32: Float32Array,
  f64: Float64Array,
  u32: Uint32Array,
  i32: Int32Array,
  u8: Uint8Array,
};

async function decodeBase64(text) {
  // fetch() of a data: URL decodes natively, fast and without a binary string of the whole block.
  try {
    const response = await fetch('data:application/octet-stream;base64,' + text);
    if (response.ok) return new Uint8Array(await response.arrayBuffer());
  } catch (error) {
    // Some browsers refuse data: URLs in fetch(); decode by hand below.
  }
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

/// { manifest, arrays }: arrays[i] is the typed array of manifest.buffers[i] (a view on the data).
export async function loadScene(doc) {
  const sceneElement = doc.getElementById('plume-scene');
  const dataElement = doc.getElementById('plume-data');
  if (!sceneElement || !dataElement) throw new Error('this page holds no Plume scene');
  const manifest = JSON.parse(sceneElement.textContent);
  if (manifest.format !== 'plume-view') throw new Error(`unknown scene format "${manifest.format}"`);
  if (manifest.version !== 1) throw new Error(`scene format version ${manifest.version}: this viewer reads version 1`);
  const bytes = await decodeBase64(dataElement.textContent.trim());
  const arrays = manifest.buffers.map((buffer, index) => {
    const Type = ARRAY_TYPES[buffer.type];
    if (!Type) throw new Error(`buffer ${index}: unknown type "${buffer.type}"`);
    const end = buffer.offset + buffer.length * Type.BYTES_PER_ELEMENT;
    if (buffer.offset % Type.BYTES_PER_ELEMENT !== 0 || end > bytes.byteLength)
      throw new Error(`buffer ${index}: bytes ${buffer.offset}..${end} lie outside the ${bytes.byteLength} of the data`);
    return new Type(bytes.buffer, bytes.byteOffset + buffer.offset, buffer.length);
  });
  // Free the base64 text: the arrays are all the page needs from now on.
  dataElement.textContent = '';
  return { manifest, arrays };
}
