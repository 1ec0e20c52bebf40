// Plays a Sylva glTF export in three.js, one level of detail at a time, with an orbit
// camera, in one of two modes:
//   clip  — the baked clip loops on the skin (the default when the file has one);
//   wind  — the engine-side wind: a static (or skinned) export animated in the vertex
//           shader from the hierarchy packed in TEXCOORD_1…3 (wind.js): trunk bend, branch
//           sway, leaf flutter, each element's phase. No skeleton: one draw per material.
// `?file=URL` picks the file (default tree.glb), `?mode=clip|wind`, `?lod=k` the level
// shown (the others come from `MSFT_lod` or `_LOD<k>` names and stay hidden), `?wind=k` the
// wind shader's strength (default 1), `?paused` stops the clock and hides the status line
// (the check script drives time through `probe`).
//
// `window.sylva` reports what was loaded and, through `probe(t)`, what the tree does at
// time t: how far each leaf joint turns its leaves relative to the joint they hang on
// (the leaves' own motion, see docs/GLTF.md), the skinned positions of sample vertices and
// the draw calls of the frame.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { addWind } from './wind.js';

const query = new URLSearchParams(location.search);
const file = query.get('file') ?? 'tree.glb';
const lod = Number(query.get('lod') ?? 0);
const paused = query.has('paused');
const status = document.getElementById('status');
if (paused) status.style.display = 'none';

const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.info.autoReset = false;
renderer.setSize(innerWidth, innerHeight);
document.body.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xa9c1d6);
scene.add(new THREE.HemisphereLight(0xdde8f4, 0x4a3f30, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 2.2);
sun.position.set(3, 6, 4);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(35, innerWidth / innerHeight, 0.05, 2000);
const controls = new OrbitControls(camera, renderer.domElement);
const clock = new THREE.Clock();
let mixer = null;

window.sylva = { ready: false, error: null };

/** The angle of a rotation matrix's rotation, degrees. */
function angleDeg(m) {
  const q = new THREE.Quaternion().setFromRotationMatrix(new THREE.Matrix4().extractRotation(m));
  return THREE.MathUtils.radToDeg(2 * Math.acos(Math.min(1, Math.abs(q.w))));
}

/** The coarser levels `MSFT_lod` names on the scene's nodes, loaded beside them (three.js
 * loads only the scene's nodes). */
async function loadLods(gltf) {
  const json = gltf.parser.json;
  for (const [i, node] of (json.nodes ?? []).entries()) {
    const ids = node.extensions?.MSFT_lod?.ids ?? [];
    if (!ids.length) continue;
    const finest = gltf.parser.associations && [...gltf.scene.children].find((o) => gltf.parser.associations.get(o)?.nodes === i);
    for (const id of ids) {
      const level = await gltf.parser.getDependency('node', id);
      (finest?.parent ?? gltf.scene).add(level);
    }
  }
}

new GLTFLoader().setMeshoptDecoder(MeshoptDecoder).load(file, async (gltf) => {
  const root = gltf.scene;
  await loadLods(gltf);
  // One level of detail: `<tree>_LOD<k>` nodes other than the chosen one are hidden.
  const lods = [];
  root.traverse((o) => { const m = /_LOD(\d+)$/.exec(o.name); if (m) lods.push([Number(m[1]), o]); });
  for (const [k, o] of lods) o.visible = k === lod;
  scene.add(root);
  root.updateMatrixWorld(true);
  const box = new THREE.Box3().setFromObject(lods.find(([k]) => k === lod)?.[1] ?? root);
  const centre = box.getCenter(new THREE.Vector3());
  const size = box.getSize(new THREE.Vector3());
  const distance = 1.2 * Math.max(size.y, size.x) / (2 * Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)));
  camera.position.set(centre.x, centre.y, centre.z + distance);
  controls.target.copy(centre);
  controls.update();

  const shown = lods.find(([k]) => k === lod)?.[1] ?? root;
  const skinned = [];
  shown.traverse((o) => { if (o.isSkinnedMesh) skinned.push(o); });
  const leaves = skinned.find((m) => m.material.name.startsWith('leaf')) ?? null;
  const clip = gltf.animations[0] ?? null;
  const mode = query.get('mode') ?? (clip ? 'clip' : 'wind');
  if (clip && mode === 'clip') {
    mixer = new THREE.AnimationMixer(root);
    mixer.clipAction(clip).play();
  }
  const wind = mode === 'wind' ? addWind(shown, { height: box.max.y, strength: Number(query.get('wind') ?? 1) }) : null;
  // Leaf joints and the joints they hang on, as indices into the leaf mesh's skeleton.
  const pairs = [];
  if (leaves) {
    const bones = leaves.skeleton.bones;
    const index = new Map(bones.map((b, i) => [b, i]));
    bones.forEach((b, i) => { if (b.name.startsWith('leaves_') && index.has(b.parent)) pairs.push([i, index.get(b.parent)]); });
  }

  window.sylva = {
    ready: true,
    error: null,
    clip: clip ? { name: clip.name, duration: clip.duration, tracks: clip.tracks.length } : null,
    lods: lods.length,
    visibleLods: lods.filter(([, o]) => o.visible).length,
    leafJoints: pairs.length,
    renderer: renderer.getContext().getParameter(renderer.getContext().VERSION),
    mode,
    windMeshes: wind?.meshes ?? 0,
    /** Poses the clip (or the wind shader) at `t` seconds with wind strength `strength`,
     * renders, and reports the leaves' turn, samples and the frame's draw calls. */
    probe(t, samples = 64, strength = null) {
      if (mixer) mixer.setTime(t);
      if (wind) wind.set(t, strength);
      scene.updateMatrixWorld(true);
      renderer.info.reset();
      renderer.render(scene, camera);
      const out = { t, leafTurnDeg: [], vertices: [], drawCalls: renderer.info.render.calls };
      if (!leaves) return out;
      const s = leaves.skeleton;
      s.update();
      const skin = (i) => new THREE.Matrix4().multiplyMatrices(s.bones[i].matrixWorld, s.boneInverses[i]);
      for (const [leaf, parent] of pairs) {
        out.leafTurnDeg.push(angleDeg(skin(parent).invert().multiply(skin(leaf))));
      }
      const n = leaves.geometry.attributes.position.count;
      const v = new THREE.Vector3();
      for (let k = 0; k < samples; k++) {
        const i = Math.floor((k + 0.5) * n / samples);
        leaves.getVertexPosition(i, v);
        out.vertices.push(v.toArray());
      }
      return out;
    },
    tick: (t) => wind?.set(t),
    /** The canvas's pixels (RGBA rows), for comparing two renders. */
    pixels() {
      const gl = renderer.getContext();
      const px = new Uint8Array(gl.drawingBufferWidth * gl.drawingBufferHeight * 4);
      gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA, gl.UNSIGNED_BYTE, px);
      return px;
    },
  };
  status.textContent = `${file}: ${mode === 'clip' ? `clip “${clip.name}”, ${clip.duration.toFixed(2)} s` : 'wind shader'}, ${pairs.length} leaf joints, LOD${lod} of ${lods.length}`;
}, undefined, (e) => {
  window.sylva = { ready: false, error: String(e?.message ?? e) };
  status.textContent = `could not load ${file}: ${window.sylva.error}`;
  console.error(window.sylva.error);
});

addEventListener('resize', () => {
  camera.aspect = innerWidth / innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(innerWidth, innerHeight);
});

renderer.setAnimationLoop(() => {
  const dt = clock.getDelta();
  if (mixer && !paused) mixer.update(dt);
  if (!paused) window.sylva.tick?.(clock.elapsedTime);
  renderer.info.reset();
  controls.update();
  renderer.render(scene, camera);
});
