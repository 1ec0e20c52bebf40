//! The kernel registry: every compute kernel by name, the WGSL sources composed (in order)
//! into its module, and its CPU twin in `sylva-core`. Pipelines are built from it
//! ([`crate::kernel::Kernel::get`]) and the naga tests validate every entry, so a kernel
//! is added in one place.
//!
//! Shared pieces (`wgsl/`) are composed in front of a kernel, never copied. A kernel's WGSL
//! sits beside the Rust that drives it (`methods/hsm/hsm_clusters.wgsl` beside
//! `methods/hsm/mod.rs`). The CPU twin has the kernel's name, binding order and loop shape,
//! and its path is checked by the compiler.

/// Quaternion helpers (`quat_rotate`, `quat_mul`), unit quaternions as `vec4<f32>(x, y, z, w)`.
pub const QUAT: &str = include_str!("wgsl/quat.wgsl");
/// The tree model's structs (`Segment`, `Stem`, `Leaf`), twins of `sylva_core::model::Raw*`.
pub const TREE: &str = include_str!("wgsl/tree.wgsl");
/// Integer hash and value noise (twin of `sylva_core::wind::noise`).
pub const NOISE: &str = include_str!("wgsl/noise.wgsl");
/// Wind fields: `Field`, `Wave`, `wind_at(p, t)`; binds the scene at bindings 0 and 1.
pub const WIND: &str = include_str!("wgsl/wind.wgsl");
/// The exact damped-oscillator step (`damped_coefficients`, `damped_apply`).
pub const OSCILLATOR: &str = include_str!("wgsl/oscillator.wgsl");

/// Kernel: wind velocity at many (x, t) samples.
pub const WIND_SAMPLE: &str = include_str!("wind/wind_sample.wgsl");
/// Kernel: segment end points from start, orientation and length.
pub const SEGMENT_ENDS: &str = include_str!("pose/segment_ends.wgsl");
/// Kernel: accumulated rotations by ancestor walk (the pose seam).
pub const POSE_ACCUMULATE: &str = include_str!("pose/pose_accumulate.wgsl");
/// Kernel: posed joint positions by ancestor walk (the pose seam).
pub const POSE_POSITIONS: &str = include_str!("pose/pose_positions.wgsl");
/// Kernel: one depth of forward kinematics, root first (the level-by-level alternative).
pub const POSE_LEVEL: &str = include_str!("pose/pose_level.wgsl");
/// Kernel: one round of pointer jumping over rotations (deep hierarchies).
pub const POSE_JUMP_ROTATIONS: &str = include_str!("pose/pose_jump_rotations.wgsl");
/// Kernel: each segment's displacement of its subtree, from accumulated rotations.
pub const POSE_JUMP_TERMS: &str = include_str!("pose/pose_jump_terms.wgsl");
/// Kernel: one round of pointer jumping over displacements.
pub const POSE_JUMP_SUMS: &str = include_str!("pose/pose_jump_sums.wgsl");
/// Kernel: joints from rest joints and summed displacements.
pub const POSE_JUMP_JOINTS: &str = include_str!("pose/pose_jump_joints.wgsl");
/// Zioma's per-frame records (`ZiomaFrame`, `ZiomaTrunk`, `ZiomaInstance`).
pub const ZIOMA: &str = include_str!("methods/zioma/zioma.wgsl");
/// Kernel: every Zioma instance's per-frame values (the trunk's lean, bands and rate).
pub const ZIOMA_FRAMES: &str = include_str!("methods/zioma/zioma_frames.wgsl");
/// Kernel: Zioma's per-segment rotations.
pub const ZIOMA_ROTATIONS: &str = include_str!("methods/zioma/zioma_rotations.wgsl");
/// Kernel: trunk noise bands at many (t, tree) samples.
pub const TRUNK_NOISE: &str = include_str!("methods/zioma/trunk_noise.wgsl");
/// Akagi's shared structs (`AkagiSegment`, `AkagiStep`).
pub const AKAGI: &str = include_str!("methods/akagi/akagi.wgsl");
/// Kernel: Akagi's own wind force per segment.
pub const AKAGI_FORCES: &str = include_str!("methods/akagi/akagi_forces.wgsl");
/// Kernel: one depth of Akagi's force propagation.
pub const AKAGI_SUBTREE: &str = include_str!("methods/akagi/akagi_subtree.wgsl");
/// Kernel: Akagi's damped angular springs.
pub const AKAGI_INTEGRATE: &str = include_str!("methods/akagi/akagi_integrate.wgsl");
/// Skjermo's shared structs and Bézier helpers.
pub const SKJERMO: &str = include_str!("methods/skjermo/skjermo.wgsl");
/// Kernel: Skjermo's re-attachment and bending.
pub const SKJERMO_STEP: &str = include_str!("methods/skjermo/skjermo_step.wgsl");
/// Kernel: seam rotations from Skjermo's curves.
pub const SKJERMO_ROTATIONS: &str = include_str!("methods/skjermo/skjermo_rotations.wgsl");
/// Kernel: one level of Skjermo's rest orientation vectors, as the device rounds them.
pub const SKJERMO_REST_ORIENT: &str = include_str!("methods/skjermo/skjermo_rest_orient.wgsl");
/// Song's linearised tree (`HsmCluster`, …) and the rotation extraction.
pub const HSM: &str = include_str!("methods/hsm/hsm.wgsl");
/// HSM stage 1's bindings, lane sums and per-cluster finish, shared by its two kernels.
pub const HSM_CLUSTER_STAGE: &str = include_str!("methods/hsm/hsm_cluster_stage.wgsl");
/// Kernel: HSM stage 1, per cluster (workgroup reduction in shared memory).
pub const HSM_CLUSTERS: &str = include_str!("methods/hsm/hsm_clusters.wgsl");
/// Kernel: HSM stage 1 with the reduction's last strides by subgroup shuffles (the same
/// additions in the same order); `SUBGROUP_SIZE` is set when the pipeline is made.
pub const HSM_CLUSTERS_SUBGROUP: &str = include_str!("methods/hsm/hsm_clusters_subgroup.wgsl");
/// Stage 3's per-particle gather (`hsm_particle_goal`), shared by two kernels.
pub const HSM_GATHER: &str = include_str!("methods/hsm/hsm_gather.wgsl");
/// Kernel: HSM stage 3, per-particle goals.
pub const HSM_GOALS: &str = include_str!("methods/hsm/hsm_goals.wgsl");
/// Stage 4's particle update (`hsm_advance`), shared by two kernels.
pub const HSM_ADVANCE: &str = include_str!("methods/hsm/hsm_advance.wgsl");
/// Kernel: HSM stage 4, per-particle integration.
pub const HSM_INTEGRATE: &str = include_str!("methods/hsm/hsm_integrate.wgsl");
/// Kernel: HSM stages 3 and 4 fused, per particle.
pub const HSM_PARTICLES: &str = include_str!("methods/hsm/hsm_particles.wgsl");
/// Kernel: leaf rotations from HSM's leaf clusters.
pub const HSM_LEAF_POSE: &str = include_str!("methods/hsm/hsm_leaf_pose.wgsl");
/// Leaf motion's structs and closed form (`LeafFrame`, `LeafMotion`, `leaf_rotation`).
pub const LEAVES: &str = include_str!("leaves/leaves.wgsl");
/// Kernel: the wind at every twig that carries leaves.
pub const LEAF_WIND: &str = include_str!("leaves/leaf_wind.wgsl");
/// Kernel: every leaf's rotation about its attachment.
pub const LEAF_FLUTTER: &str = include_str!("leaves/leaf_flutter.wgsl");
/// Kernel: seam rotations from HSM's clusters.
pub const HSM_POSE: &str = include_str!("methods/hsm/hsm_pose.wgsl");
/// The 16-byte output vertex (`Vertex`, octahedral normals), twin of `sylva_core::mesh::RawVertex`.
pub const VERTEX: &str = include_str!("mesh/vertex.wgsl");
/// Coalesced output of runs of vertices through workgroup memory (`put_vertex`, `flush_runs`).
pub const VERTEX_STAGE: &str = include_str!("mesh/vertex_stage.wgsl");
/// Per-frame meshing structs (`Ring`, `MeshInfo`, `Detail`) and the bark relief.
pub const MESH: &str = include_str!("mesh/mesh.wgsl");
/// Kernel: bark vertices of every tube.
pub const MESH_TUBES: &str = include_str!("mesh/mesh_tubes.wgsl");
/// Kernel: midpoint vertices of subdivided bark bands (§2.3).
pub const MESH_DETAIL: &str = include_str!("mesh/mesh_detail.wgsl");
/// Kernel: leaf-polygon vertices.
pub const MESH_LEAVES: &str = include_str!("mesh/mesh_leaves.wgsl");
/// Kernel: two-bone skinning of a rest mesh, instance-major.
pub const SKIN_VERTICES: &str = include_str!("mesh/skin_vertices.wgsl");
/// Kernel: Skjermo's deformer (grid → branch → bent along the Bézier).
pub const SKJERMO_DEFORM: &str = include_str!("mesh/skjermo_deform.wgsl");

/// One compute kernel of the registry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KernelDef {
    /// The kernel's name (its WGSL file's stem, and its CPU twin's function name).
    pub name: &'static str,
    /// The WGSL sources composed, in order, into its module; its entry point is `main`.
    pub sources: &'static [&'static str],
    /// The path of its CPU twin in `sylva-core` (the compiler checks that it exists).
    pub cpu_twin: &'static str,
}

macro_rules! kernels {
    ($($name:ident: [$($src:ident),* $(,)?] => $twin:path;)*) => {
        /// Every kernel: name → composed WGSL sources → CPU twin.
        pub const KERNELS: &[KernelDef] = &[
            $(KernelDef { name: stringify!($name), sources: &[$($src),*], cpu_twin: stringify!($twin) },)*
        ];
        // Each twin must exist: naming it here fails to compile when it moves or goes.
        const _: () = { $(let _ = $twin;)* };
    };
}

kernels! {
    wind_sample: [NOISE, WIND, WIND_SAMPLE] => sylva_core::wind::sample::wind_sample;
    segment_ends: [QUAT, TREE, SEGMENT_ENDS] => sylva_core::pose::segment_ends::segment_ends;
    pose_accumulate: [QUAT, TREE, POSE_ACCUMULATE] => sylva_core::pose::fk::pose_accumulate;
    pose_positions: [QUAT, TREE, POSE_POSITIONS] => sylva_core::pose::fk::pose_positions;
    pose_level: [QUAT, TREE, POSE_LEVEL] => sylva_core::pose::fk::pose_level;
    pose_jump_rotations: [QUAT, TREE, POSE_JUMP_ROTATIONS] => sylva_core::pose::fk::pose_jump_rotations;
    pose_jump_terms: [QUAT, TREE, POSE_JUMP_TERMS] => sylva_core::pose::fk::pose_jump_terms;
    pose_jump_sums: [TREE, POSE_JUMP_SUMS] => sylva_core::pose::fk::pose_jump_sums;
    pose_jump_joints: [POSE_JUMP_JOINTS] => sylva_core::pose::fk::pose_jump_joints;
    trunk_noise: [NOISE, TRUNK_NOISE] => sylva_core::methods::zioma::trunk::trunk_noise;
    zioma_frames: [NOISE, WIND, ZIOMA, ZIOMA_FRAMES] => sylva_core::methods::zioma::frames::zioma_frames;
    zioma_rotations: [QUAT, TREE, NOISE, WIND, ZIOMA, ZIOMA_ROTATIONS] => sylva_core::methods::zioma::rotations::zioma_rotations;
    akagi_forces: [QUAT, TREE, NOISE, WIND, AKAGI, AKAGI_FORCES] => sylva_core::methods::akagi::kernels::akagi_forces;
    akagi_subtree: [AKAGI_SUBTREE] => sylva_core::methods::akagi::kernels::akagi_subtree;
    akagi_integrate: [QUAT, TREE, OSCILLATOR, AKAGI, AKAGI_INTEGRATE] => sylva_core::methods::akagi::kernels::akagi_integrate;
    skjermo_step: [QUAT, TREE, NOISE, WIND, OSCILLATOR, SKJERMO, SKJERMO_STEP] => sylva_core::methods::skjermo::kernels::skjermo_step;
    skjermo_rotations: [QUAT, TREE, SKJERMO, SKJERMO_ROTATIONS] => sylva_core::methods::skjermo::kernels::skjermo_rotations;
    skjermo_rest_orient: [QUAT, TREE, SKJERMO, SKJERMO_REST_ORIENT] => sylva_core::methods::skjermo::kernels::skjermo_rest_orient;
    hsm_clusters: [QUAT, NOISE, WIND, LEAVES, HSM, HSM_CLUSTER_STAGE, HSM_CLUSTERS] => sylva_core::methods::hsm::kernels::hsm_clusters;
    hsm_clusters_subgroup: [QUAT, NOISE, WIND, LEAVES, HSM, HSM_CLUSTER_STAGE, HSM_CLUSTERS_SUBGROUP] => sylva_core::methods::hsm::kernels::hsm_clusters_subgroup;
    hsm_goals: [QUAT, HSM, HSM_GATHER, HSM_GOALS] => sylva_core::methods::hsm::kernels::hsm_goals;
    hsm_integrate: [QUAT, HSM, HSM_ADVANCE, HSM_INTEGRATE] => sylva_core::methods::hsm::kernels::hsm_integrate;
    hsm_particles: [QUAT, HSM, HSM_GATHER, HSM_ADVANCE, HSM_PARTICLES] => sylva_core::methods::hsm::kernels::hsm_particles;
    hsm_pose: [QUAT, TREE, HSM, HSM_POSE] => sylva_core::methods::hsm::kernels::hsm_pose;
    hsm_leaf_pose: [QUAT, HSM, HSM_LEAF_POSE] => sylva_core::methods::hsm::kernels::hsm_leaf_pose;
    leaf_wind: [QUAT, NOISE, WIND, LEAVES, LEAF_WIND] => sylva_core::leaves::kernels::leaf_wind;
    leaf_flutter: [QUAT, NOISE, LEAVES, LEAF_FLUTTER] => sylva_core::leaves::kernels::leaf_flutter;
    mesh_tubes: [QUAT, TREE, NOISE, MESH, VERTEX, VERTEX_STAGE, MESH_TUBES] => sylva_core::mesh::mesh_tubes;
    mesh_detail: [NOISE, MESH, VERTEX, MESH_DETAIL] => sylva_core::mesh::mesh_detail;
    mesh_leaves: [QUAT, TREE, NOISE, MESH, VERTEX, VERTEX_STAGE, MESH_LEAVES] => sylva_core::mesh::mesh_leaves;
    skin_vertices: [QUAT, NOISE, MESH, VERTEX, SKIN_VERTICES] => sylva_core::mesh::skin_vertices;
    skjermo_deform: [QUAT, TREE, NOISE, MESH, VERTEX, VERTEX_STAGE, SKJERMO, SKJERMO_DEFORM] => sylva_core::mesh::skjermo_deform;
}

/// The registered kernel `name`.
pub fn kernel(name: &str) -> Option<&'static KernelDef> {
    KERNELS.iter().find(|k| k.name == name)
}

/// Concatenates WGSL sources into one module.
pub fn compose(parts: &[&str]) -> String {
    parts.join("\n")
}
