// Engine-side wind for Sylva's glTF exports: every mesh's vertex shader moves its vertices
// from the hierarchy Sylva packs in standard channels (docs/GLTF.md, "Hierarchy data"):
//
//   TEXCOORD_1 = (depth + phase, pivot.y)   depth 0 trunk, 1 its branches, …; a leaf is its
//                                            stem's depth + 1; phase in 0…0.999
//   TEXCOORD_2 = (pivot.x, pivot.z)          where the element turns (stem base, leaf
//                                            attachment), m
//   TEXCOORD_3 = octahedral axis             the element's rest direction (stem base → tip,
//                                            a leaf's midrib)
//
// Three motions, innermost first, Zioma's hierarchy (GPU Gems 3, ch. 6) on a static mesh:
//   leaf flutter  — a leaf swings across its midrib and twists about it, about its
//                   attachment, at 3–6 Hz by its phase;
//   branch sway   — a branch (depth ≥ 1) turns about its base across the wind, at a
//                   frequency rising with depth, by its phase, less the deeper it is;
//   trunk bend    — everything leans downwind by (height / tree height)², with slow gusts,
//                   each vertex kept at its distance from the base (Zioma's normalisation).
// A static export needs no skeleton: one draw per material, as forests want.
import * as THREE from 'three';

const GLSL = /* glsl */ `
attribute vec2 sylvaA;
attribute vec2 sylvaB;
attribute vec2 sylvaC;
uniform float sylvaTime;
uniform float sylvaStrength;
uniform float sylvaHeight;
uniform vec3 sylvaWind;

vec3 sylvaAxis(vec2 e) {
  vec3 n = vec3(e.x, 1.0 - abs(e.x) - abs(e.y), e.y);
  if (n.y < 0.0) n.xz = (1.0 - abs(n.zx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.z >= 0.0 ? 1.0 : -1.0);
  return normalize(n);
}

vec3 sylvaTurn(vec3 p, vec3 pivot, vec3 axis, float angle) {
  vec3 v = p - pivot;
  float c = cos(angle), s = sin(angle);
  return pivot + v * c + cross(axis, v) * s + axis * dot(axis, v) * (1.0 - c);
}

vec3 sylvaAcross(vec3 axis) {
  vec3 a = cross(axis, sylvaWind);
  return dot(a, a) > 1e-8 ? normalize(a) : normalize(cross(vec3(0.0, 1.0, 0.0), sylvaWind));
}

vec3 sylvaMove(vec3 p) {
  const float TAU = 6.2831853;
  float depth = floor(sylvaA.x);
  float phase = fract(sylvaA.x);
  vec3 pivot = vec3(sylvaB.x, sylvaA.y, sylvaB.y);
  vec3 axis = sylvaAxis(sylvaC);
  float t = sylvaTime, k = sylvaStrength;
#ifdef SYLVA_LEAF
  float f = 3.0 + 3.0 * phase;
  p = sylvaTurn(p, pivot, sylvaAcross(axis), k * 0.25 * sin(TAU * (f * t + phase)));
  p = sylvaTurn(p, pivot, axis, k * 0.35 * sin(TAU * (1.3 * f * t + 2.0 * phase)));
#else
  if (depth >= 1.0) {
    float f = 0.5 + 0.35 * depth + 0.3 * phase;
    p = sylvaTurn(p, pivot, sylvaAcross(axis), k * 0.05 / depth * sin(TAU * (f * t + phase)));
  }
#endif
  float gust = 0.7 + 0.3 * sin(TAU * 0.07 * t) * sin(TAU * 0.19 * t + 1.3);
  float lean = k * 0.08 * (gust + 0.25 * sin(TAU * 0.3 * t));
  float h = max(p.y, 0.0) / sylvaHeight;
  float len = length(p);
  vec3 bent = p + sylvaWind * lean * h * h * sylvaHeight;
  return len > 0.0 ? normalize(bent) * len : p;
}
`;

/** Gives every mesh under `root` the wind shader. Returns `{ meshes, set(t, strength?) }`. */
export function addWind(root, { height, strength = 1, direction = new THREE.Vector3(1, 0, 0) }) {
  const uniforms = {
    sylvaTime: { value: 0 },
    sylvaStrength: { value: strength },
    sylvaHeight: { value: Math.max(height, 1e-3) },
    sylvaWind: { value: direction.clone().setY(0).normalize() },
  };
  let meshes = 0;
  root.traverse((o) => {
    const g = o.geometry;
    if (!o.isMesh || !g.attributes.uv1 || !g.attributes.uv2 || !g.attributes.uv3) return;
    g.setAttribute('sylvaA', g.attributes.uv1);
    g.setAttribute('sylvaB', g.attributes.uv2);
    g.setAttribute('sylvaC', g.attributes.uv3);
    const leaf = (o.material.name ?? '').startsWith('leaf');
    o.material = o.material.clone();
    o.material.onBeforeCompile = (shader) => {
      Object.assign(shader.uniforms, uniforms);
      shader.vertexShader = (leaf ? '#define SYLVA_LEAF\n' : '') + GLSL + shader.vertexShader.replace(
        '#include <begin_vertex>', '#include <begin_vertex>\ntransformed = sylvaMove(transformed);');
    };
    o.material.customProgramCacheKey = () => `sylva-wind-${leaf}`;
    // The wind moves vertices beyond the rest bounds.
    o.frustumCulled = false;
    meshes++;
  });
  return {
    meshes,
    set(t, k = null) {
      uniforms.sylvaTime.value = t;
      if (k !== null) uniforms.sylvaStrength.value = k;
    },
  };
}
