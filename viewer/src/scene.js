// The three.js scene of a page: the skin, the strands (Kajiya-Kay shaded lines), the guides and the
// strands the checker flags drawn over the hair (hidden only by the skin, as the preview PNGs draw
// them), and feathers' vanes when the groom has them. Frames swap the position arrays in place.
import * as THREE from 'three';

// The preview PNGs' colours (linear RGB): app/preview.h, PreviewStyle.
const SKIN = [0.62, 0.42, 0.33];
const GUIDE = [0.1, 0.85, 1.0];
const VANE = [0.55, 0.5, 0.45];

// sRGB byte to linear, as the PNG rasteriser reads the same colours.
const LINEAR = new Float32Array(256);
for (let i = 0; i < 256; ++i) {
  const c = i / 255;
  LINEAR[i] = c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4);
}

// Kajiya-Kay, with the preview's lights fixed to the camera (view space: x right, y up, z toward
// the viewer): a key light from the upper left in front, a dim fill from the right.
const HAIR_VERTEX = /* glsl */ `
attribute vec3 tangent;
attribute vec3 color;
attribute float along;
varying vec3 vTangent;
varying vec3 vColor;
varying vec3 vView;
varying float vAlong;
void main() {
  vec4 mv = modelViewMatrix * vec4(position, 1.0);
  vTangent = normalize(mat3(modelViewMatrix) * tangent);
  vView = -mv.xyz;
  vColor = color;
  vAlong = along;
  gl_Position = projectionMatrix * mv;
}`;

const HAIR_FRAGMENT = /* glsl */ `
uniform float rootShadow;
varying vec3 vTangent;
varying vec3 vColor;
varying vec3 vView;
varying float vAlong;
float sinBetween(vec3 t, vec3 d) {
  float c = dot(t, d);
  return sqrt(max(0.0, 1.0 - c * c));
}
void main() {
  vec3 t = normalize(vTangent);
  vec3 view = normalize(vView);
  vec3 key = normalize(vec3(-0.55, 0.65, 0.55));
  vec3 fill = normalize(vec3(0.8, 0.1, 0.6));
  vec3 halfKey = normalize(key + view);
  float s = sinBetween(t, halfKey);
  vec3 diffuse = vColor * (0.06 + 0.9 * sinBetween(t, key) + 0.2 * sinBetween(t, fill));
  vec3 specular = 0.07 * pow(s, 90.0) * vec3(1.0, 0.93, 0.85) + 0.5 * pow(s, 12.0) * vColor;
  float occlusion = mix(1.0, 0.3 + 0.7 * min(1.0, vAlong / 0.35), rootShadow);
  gl_FragColor = vec4(occlusion * (diffuse + specular), 1.0);
  #include <colorspace_fragment>
}`;

function hairMaterial(rootShadow) {
  return new THREE.ShaderMaterial({
    uniforms: { rootShadow: { value: rootShadow ? 1.0 : 0.0 } },
    vertexShader: HAIR_VERTEX,
    fragmentShader: HAIR_FRAGMENT,
  });
}

function linearColor(rgb) {
  return new THREE.Color().setRGB(rgb[0], rgb[1], rgb[2], THREE.LinearSRGBColorSpace);
}

// Segment indices of every strand of `offsets` (strand i: points offsets[i] .. offsets[i+1]).
function segmentIndex(offsets, strands) {
  let count = 0;
  for (const s of strands) count += Math.max(0, offsets[s + 1] - offsets[s] - 1);
  const index = new Uint32Array(2 * count);
  let k = 0;
  for (const s of strands) {
    for (let p = offsets[s]; p + 1 < offsets[s + 1]; ++p) {
      index[k++] = p;
      index[k++] = p + 1;
    }
  }
  return index;
}

function range(n) {
  const out = new Uint32Array(n);
  for (let i = 0; i < n; ++i) out[i] = i;
  return out;
}

// Unit tangents of every point (the next segment's direction; the last point takes its segment's).
function computeTangents(positions, offsets, r_tangents) {
  const strandCount = offsets.length - 1;
  for (let s = 0; s < strandCount; ++s) {
    const first = offsets[s], last = offsets[s + 1] - 1;
    for (let p = first; p <= last; ++p) {
      const a = p < last ? p : p - 1;
      if (a < first) {
        r_tangents[3 * p] = 0;
        r_tangents[3 * p + 1] = 1;
        r_tangents[3 * p + 2] = 0;
        continue;
      }
      const dx = positions[3 * a + 3] - positions[3 * a];
      const dy = positions[3 * a + 4] - positions[3 * a + 1];
      const dz = positions[3 * a + 5] - positions[3 * a + 2];
      const length = Math.hypot(dx, dy, dz) || 1;
      r_tangents[3 * p] = dx / length;
      r_tangents[3 * p + 1] = dy / length;
      r_tangents[3 * p + 2] = dz / length;
    }
  }
}

function alongStrands(offsets) {
  const along = new Float32Array(offsets[offsets.length - 1]);
  for (let s = 0; s + 1 < offsets.length; ++s) {
    const n = offsets[s + 1] - offsets[s];
    for (let i = 0; i < n; ++i) along[offsets[s] + i] = n > 1 ? i / (n - 1) : 0;
  }
  return along;
}

export class PlumeScene {
  constructor(manifest, arrays) {
    this.manifest = manifest;
    this.arrays = arrays;
    this.main = new THREE.Scene();
    this.skinDepth = new THREE.Scene();  // the skin again, depth only, for the overlays
    this.overlay = new THREE.Scene();
    this.frameIndex = -1;
    this.mode = 'plain';

    // Skin: positions per frame, normals computed on each.
    const skin = manifest.skin;
    this.skinGeometry = new THREE.BufferGeometry();
    this.skinGeometry.setIndex(new THREE.BufferAttribute(arrays[skin.triangles], 1));
    this.skinGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * skin.vertex_count), 3));
    this.skin = new THREE.Mesh(
      this.skinGeometry,
      new THREE.MeshStandardMaterial({ color: linearColor(SKIN), roughness: 0.7, metalness: 0, side: THREE.DoubleSide }),
    );
    this.main.add(this.skin);
    this.skinDepth.add(new THREE.Mesh(this.skinGeometry, new THREE.MeshBasicMaterial({ colorWrite: false, side: THREE.DoubleSide })));

    // Strands: one set of line segments; positions swapped per frame.
    const strands = manifest.strands;
    this.strandOffsets = arrays[strands.offsets];
    this.strandCount = this.strandOffsets.length - 1;
    const pointCount = this.strandOffsets[this.strandCount];
    this.strandGeometry = new THREE.BufferGeometry();
    this.strandGeometry.setIndex(new THREE.BufferAttribute(segmentIndex(this.strandOffsets, range(this.strandCount)), 1));
    this.strandGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * pointCount), 3));
    this.strandGeometry.setAttribute('tangent', new THREE.BufferAttribute(new Float32Array(3 * pointCount), 3));
    this.strandGeometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * pointCount), 3));
    this.strandGeometry.setAttribute('along', new THREE.BufferAttribute(alongStrands(this.strandOffsets), 1));
    this.strands = new THREE.LineSegments(this.strandGeometry, hairMaterial(true));
    this.strands.frustumCulled = false;
    this.main.add(this.strands);
    // The strands the checker flags, over the others: the same attributes, their own segments.
    this.flaggedGeometry = new THREE.BufferGeometry();
    for (const name of ['position', 'tangent', 'color', 'along'])
      this.flaggedGeometry.setAttribute(name, this.strandGeometry.getAttribute(name));
    this.flaggedGeometry.setIndex(new THREE.BufferAttribute(new Uint32Array(0), 1));
    this.flagged = new THREE.LineSegments(this.flaggedGeometry, hairMaterial(true));
    this.flagged.frustumCulled = false;
    this.overlay.add(this.flagged);

    // One strand picked or found by id, in white over everything but the skin.
    this.selectedGeometry = new THREE.BufferGeometry();
    this.selectedGeometry.setAttribute('position', this.strandGeometry.getAttribute('position'));
    this.selectedGeometry.setIndex(new THREE.BufferAttribute(new Uint32Array(0), 1));
    this.selected = new THREE.LineSegments(this.selectedGeometry, new THREE.LineBasicMaterial({ color: 0xffffff }));
    this.selected.frustumCulled = false;
    this.selected.renderOrder = 1;
    this.overlay.add(this.selected);
    this.selectedStrand = -1;

    // Guides, drawn over the strands.
    const guides = manifest.guides;
    this.guideOffsets = arrays[guides.offsets];
    this.guideGeometry = new THREE.BufferGeometry();
    this.guideGeometry.setIndex(new THREE.BufferAttribute(segmentIndex(this.guideOffsets, range(guides.count)), 1));
    this.guideGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * this.guideOffsets[guides.count]), 3));
    this.guides = new THREE.LineSegments(this.guideGeometry, new THREE.LineBasicMaterial({ color: linearColor(GUIDE) }));
    this.guides.frustumCulled = false;
    this.guides.visible = false;
    this.overlay.add(this.guides);

    // Feathers' vanes: a triangle mesh per frame.
    this.vanes = null;
    if (manifest.vanes) {
      this.vaneGeometry = new THREE.BufferGeometry();
      this.vaneGeometry.setIndex(new THREE.BufferAttribute(arrays[manifest.vanes.triangles], 1));
      this.vaneGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(arrays[manifest.vanes.positions[0]].length), 3));
      this.vanes = new THREE.Mesh(
        this.vaneGeometry,
        new THREE.MeshStandardMaterial({ color: linearColor(VANE), roughness: 0.8, side: THREE.DoubleSide }),
      );
      this.vanes.frustumCulled = false;
      this.main.add(this.vanes);
    }

    // Lights follow the camera, as the PNG's do.
    this.camera = new THREE.PerspectiveCamera(manifest.camera.fov, 1, 1e-3, 1e3);
    const key = new THREE.DirectionalLight(0xffffff, 1.7);
    key.position.set(-0.55, 0.65, 0.55);
    const fill = new THREE.DirectionalLight(0xffffff, 0.45);
    fill.position.set(0.8, 0.1, 0.6);
    this.camera.add(key, fill);
    this.main.add(this.camera, new THREE.HemisphereLight(0xe0dcd8, 0x302820, 0.35));

    this.modes = new Map(manifest.colors.map((entry) => [entry.mode, entry]));
  }

  /// Shows frame `index` of manifest.frames.
  setFrame(index) {
    const m = this.manifest, a = this.arrays;
    if (index === this.frameIndex) return;
    this.frameIndex = index;
    const copy = (geometry, name, source) => {
      const attribute = geometry.getAttribute(name);
      attribute.array.set(source);
      attribute.needsUpdate = true;
    };
    copy(this.skinGeometry, 'position', a[m.skin.positions[index]]);
    this.skinGeometry.computeVertexNormals();
    const positions = a[m.strands.positions[index]];
    copy(this.strandGeometry, 'position', positions);
    this.strandGeometry.boundingSphere = null;  // picking bounds the strands anew
    const tangents = this.strandGeometry.getAttribute('tangent');
    computeTangents(positions, this.strandOffsets, tangents.array);
    tangents.needsUpdate = true;
    copy(this.guideGeometry, 'position', a[m.guides.positions[index]]);
    if (this.vanes) {
      copy(this.vaneGeometry, 'position', a[m.vanes.positions[index]]);
      this.vaneGeometry.computeVertexNormals();
    }
    if (this.mode === 'problems') this.applyColors();
  }

  /// Colours the strands by `mode` (one of manifest.colors' modes).
  setMode(mode) {
    if (!this.modes.has(mode)) throw new Error(`unknown colour mode "${mode}"`);
    this.mode = mode;
    this.applyColors();
  }

  /// The checker's flags of the shown strands at the current frame.
  flags() {
    return this.arrays[this.manifest.check.frames[this.frameIndex].flags];
  }

  applyColors() {
    const colors = this.strandGeometry.getAttribute('color');
    const out = colors.array;
    const offsets = this.strandOffsets;
    let perStrand;
    let flagged = [];
    if (this.mode === 'problems') {
      // Flags: 1 inside the skin, 2 crossing (transversal), 4 touching (near-parallel). Violations
      // (inside, crossing) are drawn over the other strands; touching is not one.
      const palette = this.manifest.check.palette;
      const byFlags = [palette.clean, palette.inside, palette.crossing, palette.both];
      const flags = this.flags();
      perStrand = new Uint8Array(3 * this.strandCount);
      for (let s = 0; s < this.strandCount; ++s) {
        const violation = flags[s] & 3;
        perStrand.set(violation || !(flags[s] & 4) ? byFlags[violation] : palette.touching, 3 * s);
        if (violation) flagged.push(s);
      }
    } else {
      perStrand = this.arrays[this.modes.get(this.mode).colors];
    }
    for (let s = 0; s < this.strandCount; ++s) {
      const r = LINEAR[perStrand[3 * s]], g = LINEAR[perStrand[3 * s + 1]], b = LINEAR[perStrand[3 * s + 2]];
      for (let p = offsets[s]; p < offsets[s + 1]; ++p) {
        out[3 * p] = r;
        out[3 * p + 1] = g;
        out[3 * p + 2] = b;
      }
    }
    colors.needsUpdate = true;
    this.flaggedGeometry.setIndex(new THREE.BufferAttribute(segmentIndex(offsets, flagged), 1));
  }

  /// Shows strand `strand` (an index among the shown strands; -1: none) in white.
  select(strand) {
    this.selectedStrand = strand;
    this.selectedGeometry.setIndex(new THREE.BufferAttribute(segmentIndex(this.strandOffsets, strand >= 0 ? [strand] : []), 1));
  }

  /// The strand under `raycaster`'s ray within `threshold` (world units), in front of the skin when
  /// the skin is shown; -1 when none.
  pick(raycaster, threshold) {
    if (!this.strands.visible) return -1;
    raycaster.params.Line.threshold = threshold;
    const hits = raycaster.intersectObject(this.strands, false);
    if (hits.length === 0) return -1;
    let skin = Infinity;
    if (this.skin.visible) {
      const skinHits = raycaster.intersectObject(this.skin, false);
      if (skinHits.length) skin = skinHits[0].distance + threshold;
    }
    const hit = hits.find((h) => h.distance <= skin);
    if (!hit) return -1;
    const point = this.strandGeometry.index.getX(hit.index);
    // The strand holding the point: offsets ascend.
    let low = 0, high = this.strandCount - 1;
    while (low < high) {
      const mid = (low + high + 1) >> 1;
      if (this.strandOffsets[mid] <= point) low = mid;
      else high = mid - 1;
    }
    return low;
  }

  /// Draws the frame: the skin and the hair, then over them (tested against the skin's depth only)
  /// the flagged strands and the guides.
  render(renderer) {
    renderer.clear();
    renderer.render(this.main, this.camera);
    renderer.clearDepth();
    renderer.render(this.skinDepth, this.camera);
    renderer.render(this.overlay, this.camera);
  }
}
