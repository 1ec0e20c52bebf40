//! WGSL sources. Shared pieces are separate files composed in front of each kernel
//! ([`compose`]), so no WGSL is copied between kernels.

/// Quaternion helpers (`quat_rotate`, `quat_mul`), unit quaternions as `vec4<f32>(x, y, z, w)`.
pub const QUAT: &str = include_str!("quat.wgsl");
/// The tree model's structs (`Segment`, `Stem`, `Leaf`), twins of `sylva_core::model::Raw*`.
pub const TREE: &str = include_str!("tree.wgsl");
/// Integer hash and value noise (twin of `sylva_core::cpu::noise`).
pub const NOISE: &str = include_str!("noise.wgsl");
/// Wind fields: `Field`, `Wave`, `wind_at(p, t)`; binds the scene at bindings 0 and 1.
pub const WIND: &str = include_str!("wind.wgsl");
/// Kernel: segment end points from start, orientation and length.
pub const SEGMENT_ENDS: &str = include_str!("segment_ends.wgsl");
/// Kernel: wind velocity at many (x, t) samples.
pub const WIND_SAMPLE: &str = include_str!("wind_sample.wgsl");
/// Kernel: accumulated rotations by ancestor walk (the pose seam).
pub const POSE_ACCUMULATE: &str = include_str!("pose_accumulate.wgsl");
/// Kernel: posed joint positions by ancestor walk (the pose seam).
pub const POSE_POSITIONS: &str = include_str!("pose_positions.wgsl");
/// Kernel: one depth of forward kinematics, root first (the level-by-level alternative).
pub const POSE_LEVEL: &str = include_str!("pose_level.wgsl");
/// Kernel: Zioma's per-segment rotations.
pub const ZIOMA_ROTATIONS: &str = include_str!("zioma_rotations.wgsl");
/// Akagi's shared structs (`AkagiSegment`, `AkagiStep`).
pub const AKAGI: &str = include_str!("akagi.wgsl");
/// Kernel: Akagi's own wind force per segment.
pub const AKAGI_FORCES: &str = include_str!("akagi_forces.wgsl");
/// Kernel: one depth of Akagi's force propagation.
pub const AKAGI_SUBTREE: &str = include_str!("akagi_subtree.wgsl");
/// Kernel: Akagi's damped angular springs.
pub const AKAGI_INTEGRATE: &str = include_str!("akagi_integrate.wgsl");
/// Skjermo's shared structs and Bézier helpers.
pub const SKJERMO: &str = include_str!("skjermo.wgsl");
/// Kernel: Skjermo's re-attachment and bending.
pub const SKJERMO_STEP: &str = include_str!("skjermo_step.wgsl");
/// Kernel: seam rotations from Skjermo's curves.
pub const SKJERMO_ROTATIONS: &str = include_str!("skjermo_rotations.wgsl");
/// Kernel: one level of Skjermo's rest orientation vectors, as the device rounds them.
pub const SKJERMO_REST_ORIENT: &str = include_str!("skjermo_rest_orient.wgsl");
/// Song's linearised tree (`HsmCluster`, …) and the rotation extraction.
pub const HSM: &str = include_str!("hsm.wgsl");
/// Kernel: HSM stage 1, per cluster (workgroup reduction).
pub const HSM_CLUSTERS: &str = include_str!("hsm_clusters.wgsl");
/// Stage 3's per-particle gather (`hsm_particle_goal`), shared by two kernels.
pub const HSM_GATHER: &str = include_str!("hsm_gather.wgsl");
/// Kernel: HSM stage 3, per-particle goals.
pub const HSM_GOALS: &str = include_str!("hsm_goals.wgsl");
/// Stage 4's particle update (`hsm_advance`), shared by two kernels.
pub const HSM_ADVANCE: &str = include_str!("hsm_advance.wgsl");
/// Kernel: HSM stage 4, per-particle integration.
pub const HSM_INTEGRATE: &str = include_str!("hsm_integrate.wgsl");
/// Kernel: HSM stages 3 and 4 fused, per particle.
pub const HSM_PARTICLES: &str = include_str!("hsm_particles.wgsl");
/// Kernel: seam rotations from HSM's clusters.
pub const HSM_POSE: &str = include_str!("hsm_pose.wgsl");
/// Per-frame meshing structs (`Ring`, `MeshInfo`, `Detail`, `Vertex`) and the bark relief.
pub const MESH: &str = include_str!("mesh.wgsl");
/// Kernel: bark vertices of every tube.
pub const MESH_TUBES: &str = include_str!("mesh_tubes.wgsl");
/// Kernel: midpoint vertices of subdivided bark bands (§2.3).
pub const MESH_DETAIL: &str = include_str!("mesh_detail.wgsl");
/// Kernel: leaf-polygon vertices.
pub const MESH_LEAVES: &str = include_str!("mesh_leaves.wgsl");
/// Kernel: two-bone skinning of a rest mesh, instance-major.
pub const SKIN_VERTICES: &str = include_str!("skin_vertices.wgsl");
/// Kernel: Skjermo's deformer (grid → branch → bent along the Bézier).
pub const SKJERMO_DEFORM: &str = include_str!("skjermo_deform.wgsl");
/// Kernel: trunk noise bands at many (t, tree) samples.
pub const TRUNK_NOISE: &str = include_str!("trunk_noise.wgsl");

/// Every kernel, as (name, the sources composed in order). Tests validate each with naga.
pub const KERNELS: &[(&str, &[&str])] = &[
    ("segment_ends", &[QUAT, TREE, SEGMENT_ENDS]),
    ("wind_sample", &[NOISE, WIND, WIND_SAMPLE]),
    ("trunk_noise", &[NOISE, TRUNK_NOISE]),
    ("pose_accumulate", &[QUAT, TREE, POSE_ACCUMULATE]),
    ("pose_positions", &[QUAT, TREE, POSE_POSITIONS]),
    ("pose_level", &[QUAT, TREE, POSE_LEVEL]),
    ("zioma_rotations", &[QUAT, TREE, NOISE, WIND, ZIOMA_ROTATIONS]),
    ("akagi_forces", &[QUAT, TREE, NOISE, WIND, AKAGI, AKAGI_FORCES]),
    ("akagi_subtree", &[AKAGI_SUBTREE]),
    ("akagi_integrate", &[QUAT, TREE, AKAGI, AKAGI_INTEGRATE]),
    ("skjermo_step", &[QUAT, TREE, NOISE, WIND, SKJERMO, SKJERMO_STEP]),
    ("skjermo_rotations", &[QUAT, TREE, SKJERMO, SKJERMO_ROTATIONS]),
    ("skjermo_rest_orient", &[QUAT, TREE, SKJERMO, SKJERMO_REST_ORIENT]),
    ("hsm_clusters", &[QUAT, NOISE, WIND, HSM, HSM_CLUSTERS]),
    ("hsm_goals", &[QUAT, HSM, HSM_GATHER, HSM_GOALS]),
    ("hsm_integrate", &[QUAT, HSM, HSM_ADVANCE, HSM_INTEGRATE]),
    ("hsm_particles", &[QUAT, HSM, HSM_GATHER, HSM_ADVANCE, HSM_PARTICLES]),
    ("hsm_pose", &[QUAT, TREE, HSM, HSM_POSE]),
    ("mesh_tubes", &[QUAT, TREE, NOISE, MESH, MESH_TUBES]),
    ("mesh_detail", &[NOISE, MESH, MESH_DETAIL]),
    ("mesh_leaves", &[QUAT, TREE, NOISE, MESH, MESH_LEAVES]),
    ("skin_vertices", &[QUAT, NOISE, MESH, SKIN_VERTICES]),
    ("skjermo_deform", &[QUAT, TREE, NOISE, MESH, SKJERMO, SKJERMO_DEFORM]),
];

/// Concatenates WGSL sources into one module.
pub fn compose(parts: &[&str]) -> String {
    parts.join("\n")
}
