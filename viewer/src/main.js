// Plume's viewer: the page `plume view` writes opens from disk, reads the scene it carries and
// shows it with three.js: orbit (left drag), zoom (wheel), pan (right drag), a frame slider and
// play for a range, colours by attribute and by the checker's problems.
//
// For tests and scripts the page exposes window.plumeViewer (state, counts, setFrame, setMode,
// strandScreenBox) and sets <html data-plume-state="ready"> once the first frame is drawn, or
// "error" with the message in #plume-error.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { loadScene } from './data.js';
import { PlumeScene } from './scene.js';
import { buildPanel } from './panel.js';
import css from './style.css';

const api = { state: 'loading', renderCount: 0 };
window.plumeViewer = api;

function setState(state) {
  api.state = state;
  document.documentElement.dataset.plumeState = state;
}

// The distance at which a camera looking along -toEye sees every corner of `box` with a 6% margin
// (the preview's fit, app/preview.cpp).
function fittedDistance(box, toEye, up, fovDegrees) {
  const center = box.getCenter(new THREE.Vector3());
  const radius = Math.max(0.5 * box.getSize(new THREE.Vector3()).length(), 1e-6);
  const halfFov = (0.5 * fovDegrees * Math.PI) / 180;
  const limit = 0.94 * Math.tan(halfFov);
  const forward = toEye.clone().negate();
  const right = forward.clone().cross(up).normalize();
  const upView = right.clone().cross(forward);
  const corner = new THREE.Vector3();
  const fits = (distance) => {
    const eye = center.clone().addScaledVector(toEye, distance);
    for (let i = 0; i < 8; ++i) {
      corner.set(i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y, i & 4 ? box.max.z : box.min.z).sub(eye);
      const z = corner.dot(forward);
      if (z <= 0 || Math.abs(corner.dot(right)) > limit * z || Math.abs(corner.dot(upView)) > limit * z) return false;
    }
    return true;
  };
  let far = (radius / Math.sin(halfFov)) * 1.05, near = radius;
  if (fits(near)) far = near;
  for (let i = 0; i < 40 && far - near > 1e-4 * far; ++i) {
    const mid = 0.5 * (near + far);
    if (fits(mid)) far = mid;
    else near = mid;
  }
  return far;
}

function placeCamera(scene, controls) {
  const m = scene.manifest;
  const box = new THREE.Box3(new THREE.Vector3(...m.bounds.min), new THREE.Vector3(...m.bounds.max));
  const up = new THREE.Vector3(...m.up).normalize();
  const front = new THREE.Vector3(...m.front);
  front.addScaledVector(up, -front.dot(up)).normalize();
  const azimuth = (m.camera.azimuth * Math.PI) / 180, elevation = (m.camera.elevation * Math.PI) / 180;
  const horizontal = front.clone().applyAxisAngle(up, azimuth);
  const toEye = horizontal.clone().multiplyScalar(Math.cos(elevation)).addScaledVector(up, Math.sin(elevation)).normalize();
  const pictureUp = horizontal.clone().multiplyScalar(-Math.sin(elevation)).addScaledVector(up, Math.cos(elevation)).normalize();
  const distance = fittedDistance(box, toEye, pictureUp, m.camera.fov);
  const center = box.getCenter(new THREE.Vector3());
  const size = box.getSize(new THREE.Vector3()).length();
  scene.camera.up.copy(up);
  scene.camera.position.copy(center).addScaledVector(toEye, distance);
  controls.target.copy(center);
  controls.minDistance = 0.02 * size;
  controls.maxDistance = 20 * size;
  controls.update();
  fitClipping(scene.camera, center, size);
}

// Near and far planes around the scene's bounding sphere (radius: the box's diagonal, which leaves
// room for strands that swing out of the rest bounds), wherever the camera has gone.
function fitClipping(camera, center, size) {
  const distance = camera.position.distanceTo(center);
  camera.near = Math.max(distance - size, distance * 1e-3, size * 1e-4);
  camera.far = distance + size;
  camera.updateProjectionMatrix();
}

// True when WebGL runs in software (the renderer's name, where the browser tells it).
function softwareRenderer() {
  const gl = document.createElement('canvas').getContext('webgl2');
  if (!gl) return false;
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  gl.getExtension('WEBGL_lose_context')?.loseContext();
  return /swiftshader|llvmpipe|software/i.test(name);
}

async function start() {
  const started = performance.now();
  const style = document.createElement('style');
  style.textContent = css;
  document.head.appendChild(style);

  const { manifest, arrays } = await loadScene(document);
  const scene = new PlumeScene(manifest, arrays);
  const dataMilliseconds = performance.now();

  const canvas = document.createElement('canvas');
  canvas.id = 'plume-canvas';
  document.body.appendChild(canvas);
  // A software renderer (SwiftShader, llvmpipe: no GPU, as in many virtual machines) draws the lines
  // on the CPU: without multisampling and at one sample a pixel it stays interactive.
  const software = softwareRenderer();
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: !software, alpha: true, preserveDrawingBuffer: true });
  renderer.autoClear = false;
  renderer.setClearColor(0x000000, 0);
  renderer.setPixelRatio(software ? 1 : window.devicePixelRatio || 1);
  const controls = new OrbitControls(scene.camera, canvas);

  let pending = false;
  const draw = () => {
    pending = false;
    scene.render(renderer);
    api.renderCount += 1;
  };
  const requestDraw = () => {
    if (!pending) {
      pending = true;
      requestAnimationFrame(draw);
    }
  };
  const resize = () => {
    const width = window.innerWidth, height = window.innerHeight;
    renderer.setSize(width, height);
    scene.camera.aspect = width / Math.max(height, 1);
    scene.camera.updateProjectionMatrix();
    requestDraw();
  };
  window.addEventListener('resize', resize);
  const box = new THREE.Box3(new THREE.Vector3(...manifest.bounds.min), new THREE.Vector3(...manifest.bounds.max));
  const center = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3()).length();
  controls.addEventListener('change', () => {
    fitClipping(scene.camera, center, size);
    requestDraw();
  });

  const panel = buildPanel(document, manifest, scene, requestDraw);

  // A click (a press and release without a drag) picks the strand under the pointer.
  const raycaster = new THREE.Raycaster();
  let pressed = null;
  canvas.addEventListener('pointerdown', (event) => {
    pressed = event.button === 0 ? { x: event.clientX, y: event.clientY } : null;
  });
  canvas.addEventListener('pointerup', (event) => {
    if (!pressed || Math.hypot(event.clientX - pressed.x, event.clientY - pressed.y) > 4) return;
    const rect = canvas.getBoundingClientRect();
    const pointer = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
      -((event.clientY - rect.top) / rect.height) * 2 + 1);
    raycaster.setFromCamera(pointer, scene.camera);
    // Four pixels at the orbit's centre, in world units.
    const distance = scene.camera.position.distanceTo(controls.target);
    const perPixel = (2 * distance * Math.tan((scene.camera.fov * Math.PI) / 360)) / rect.height;
    panel.selectIndex(scene.pick(raycaster, 4 * perPixel));
  });
  placeCamera(scene, controls);
  scene.setFrame(0);
  scene.setMode('plain');
  panel.update();
  resize();
  draw();
  // Ready once the first frame has reached the screen: the browser starts a frame after the one
  // that drew it.
  await new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve)));

  const loadMilliseconds = performance.now();
  Object.assign(api, {
    manifest,
    strandsTotal: manifest.strands.total,
    strandsShown: manifest.strands.shown,
    frames: manifest.frames,
    setFrame: (index) => panel.setFrame(index),
    setMode: (mode) => panel.setMode(mode),
    /// Selects the strand with this stable id; its index among the shown strands, or -1.
    selectStrand: (id) => panel.selectId(id),
    /// The box (CSS pixels: left, top, right, bottom) holding every shown strand point of the
    /// current frame as drawn now.
    strandScreenBox() {
      const positions = arrays[manifest.strands.positions[scene.frameIndex]];
      const p = new THREE.Vector3();
      const box = { left: Infinity, top: Infinity, right: -Infinity, bottom: -Infinity };
      scene.camera.updateMatrixWorld();
      for (let i = 0; i < positions.length; i += 3) {
        p.set(positions[i], positions[i + 1], positions[i + 2]).project(scene.camera);
        const x = ((p.x + 1) / 2) * window.innerWidth, y = ((1 - p.y) / 2) * window.innerHeight;
        box.left = Math.min(box.left, x);
        box.right = Math.max(box.right, x);
        box.top = Math.min(box.top, y);
        box.bottom = Math.max(box.bottom, y);
      }
      return box;
    },
    /// Milliseconds from the navigation: to the scene read (parsed, decoded, its geometry built)
    /// and to the first frame drawn; and the part of the latter spent in this script.
    dataMilliseconds,
    loadMilliseconds,
    scriptMilliseconds: loadMilliseconds - started,
    software,
  });
  Object.defineProperties(api, {
    frameIndex: { get: () => scene.frameIndex, enumerable: true },
    mode: { get: () => scene.mode, enumerable: true },
    selectedStrand: { get: () => (scene.selectedStrand >= 0 ? arrays[manifest.strands.ids][scene.selectedStrand] : null), enumerable: true },
  });
  setState('ready');
}

function showError(error) {
  const box = document.createElement('pre');
  box.id = 'plume-error';
  box.textContent = `Plume viewer: ${error && error.message ? error.message : error}`;
  document.body.appendChild(box);
  api.error = box.textContent;
  setState('error');
  console.error(box.textContent);
}

start().catch(showError);
