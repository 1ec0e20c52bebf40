//! glTF 2.0 export: the tree's mesh with PBR materials and embedded textures, a skin, an
//! animation baked from any method, hierarchy attributes for engine-side wind shaders, and
//! level-of-detail meshes. `.glb` (binary, one file) or `.gltf` (JSON with the buffer and
//! textures embedded as data URIs, also one file), written atomically.
//!
//! # Skin
//!
//! Joints are nodes under an `armature` node, one per segment ([`JointMode::Segment`]) or
//! one per stem ([`JointMode::Stem`], for engines with a bone limit). Every joint's rest
//! frame is its driving segment's joint position with the world axes (inverse bind matrix
//! a pure translation), so a joint's world transform at a frame is exactly Sylva's bone
//! transform `x ↦ j + D (x − j_rest)` ([`crate::mesh::skin`]). Vertices carry at most two
//! joints (`JOINTS_0` u16, `WEIGHTS_0` float, summing to 1): a bark vertex blends its
//! segment with the neighbour toward the nearer joint; a leaf vertex blends its segment's
//! joint into its leaf joint by its blade coordinate `v` (below).
//!
//! **Leaf joints** ([`GltfOptions::leaf_joints`]): every joint carrying leaves gets a child
//! joint pivoting at the mean of its leaves' attachments, keyed with the normalised sum of
//! their rotations relative to their segment (the least-squares single turn of the group).
//! Weighting a leaf vertex `v` (0 at the attachment, 1 at the tip) on the leaf joint keeps
//! the attachment exactly on the twig while the blade turns. What differs from leaf to leaf
//! (each leaf's flutter phase) is left to an engine shader through `_LEAF_FLUTTER`.
//!
//! **Merging per stem**: stem `k`'s joint is driven by the stem's first segment (its base),
//! and every vertex of the stem is bound to it, so a stem moves as a rigid body about its
//! base. The blend toward the neighbouring segment is kept only where that segment belongs
//! to another stem (never, for tubes: stems do not share rings), so bends *within* a stem
//! are lost — the price of one bone per stem.
//!
//! # Animation
//!
//! One clip, `wind` (`wind_loop` when it loops: the suffix Godot's importer loops by), with a key per frame of the [`Clip`] (linear interpolation): a
//! rotation channel per joint that moves (leaf joints included), and a translation channel for a joint whose
//! offset from its parent changes. The four methods pose by forward kinematics, so their
//! clips need rotations only; a clip whose joints leave their parents' (a pose from
//! cluster centres, say) gets translations too. Consecutive rotation keys are kept in the
//! same hemisphere so interpolation takes the short way.
//!
//! # Hierarchy attributes (Pivot Painter style)
//!
//! Every vertex also carries, in the rest pose and metres (custom attributes, float):
//!
//! * `_PIVOT` (VEC3): where its element rotates — the base of its stem for bark, the
//!   attachment point for a leaf;
//! * `_BRANCH_AXIS` (VEC3, unit): the element's rest direction — base to tip of the stem,
//!   the blade's midrib for a leaf;
//! * `_HIERARCHY_DEPTH` (SCALAR): 0 trunk, 1 its branches, …; a leaf is its stem's depth + 1;
//! * `_PARENT_PIVOT` (VEC3): the pivot of the element it hangs on (the trunk: its own);
//! * `_PHASE` (SCALAR, 0…1): a random number per element (stable per tree and seed), for
//!   Zioma's per-branch phase shift;
//! * `_LEAF_FLUTTER` (VEC3, leaves only): the leaf's swing and twist frequencies (Hz) and
//!   flutter amplitude (rad), from [`crate::leaves::LeafFlutter`].
//!
//! With these an engine shader can rotate each vertex about `_PIVOT` around an axis
//! perpendicular to `_BRANCH_AXIS` and the wind, then about `_PARENT_PIVOT`, scaling the
//! motion with depth — Zioma's hierarchy on a static mesh. `docs/GLTF.md` gives a shader.
//!
//! # Levels of detail
//!
//! Each [`Lod`] is a separate mesh (`<tree>_LOD0`, `_LOD1`, …, the engines' naming) on its
//! own node, all bound to the same skin: fewer tube sides, fewer rings per segment, fewer
//! leaf sides and fewer (larger) leaves ([`MeshLayout::thin_leaves`]).

mod builder;
mod cards;
mod meshopt;
mod rig;
mod target;

pub use builder::{PHASE_MAX, octahedral, octahedral_decode, reduce_keys};
pub use rig::tangents;
pub use target::{Budget, CARD_TRIANGLES, GAME_BUDGET, KEY_TOLERANCE_DEG, Target, bark_triangles, game_lods};

use super::bake::Clip;
use super::textures;
use crate::io::write_atomic;
use crate::mesh::{MeshError, MeshLayout, MeshParams, RawSkin, RawVertex, SkinLayout, Uv};
use crate::model::{NONE, RawLeaf, Tree};
use builder::{Builder, Format};
use glam::{Mat4, Quat, Vec3, Vec4};
use gltf::json;
use json::validation::{Checked::Valid, USize64};
use rig::{Geometry, Hierarchy, Rig};
use std::borrow::Cow;
use std::path::Path;

/// What a skin joint stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum JointMode {
    /// One joint per segment: the full motion.
    #[default]
    Segment,
    /// One joint per stem, driven by its base segment (see the module documentation).
    Stem,
    /// At most this many joints, leaf joints included: the thickest segments head joints
    /// (a stem's base first), every other segment rides with the joint of the segment it
    /// hangs on — thin stems merge into their parents by size. Game engines' skin budget.
    Budget(usize),
}

impl JointMode {
    fn as_str(self) -> &'static str {
        match self {
            Self::Segment => "one per segment",
            Self::Stem => "one per stem",
            Self::Budget(_) => "thickest segments within a budget",
        }
    }
}

/// One level of detail.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lod {
    /// Tube sides.
    pub sides: u32,
    /// Rings per segment.
    pub samples: u32,
    /// Leaf polygon sides.
    pub leaf_sides: u32,
    /// Fraction of the leaves kept (0…1], the rest scaled up to keep the leaf area.
    pub leaf_keep: f32,
    /// Stems thinner than this at their base (m) get no bark (0: every stem); their leaves
    /// stay, on the segments they hang on.
    pub min_radius: f32,
    /// Leaves as leaf cards: a square alpha-masked quad per kept leaf carrying four blades
    /// on a twig (`textures::leaf_card_png`), two triangles, instead of a blade polygon.
    pub cards: bool,
    /// Subdivide the bark's long displaced bands (`MeshParams::subdivide_min_edge`).
    pub subdivide: bool,
}

impl Lod {
    /// A film level: every stem, blade polygons, subdivided bark.
    pub const fn film(sides: u32, samples: u32, leaf_sides: u32, leaf_keep: f32) -> Self {
        Self { sides, samples, leaf_sides, leaf_keep, min_radius: 0.0, cards: false, subdivide: true }
    }
}

/// The film levels: full detail; about half; about a fifth.
pub const DEFAULT_LODS: [Lod; 3] = [Lod::film(8, 3, 8, 1.0), Lod::film(6, 2, 6, 0.5), Lod::film(4, 1, 4, 0.25)];

/// Export options.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfOptions {
    /// Joints per segment or per stem.
    pub joints: JointMode,
    /// Refuse to write more joints than this (an engine's bone limit).
    pub max_joints: Option<usize>,
    /// Levels of detail, finest first (at least one).
    pub lods: Vec<Lod>,
    /// A leaf joint for every joint that carries leaves, turning them in the clip (see the
    /// module documentation); off, leaves are rigid with their joint in the clip.
    pub leaf_joints: bool,
    /// Compact vertex data (see "Compact data" in the module documentation).
    pub quantize: bool,
    /// The hierarchy also in the custom float attributes `_PIVOT`, `_BRANCH_AXIS`, …
    /// (it is always packed in `TEXCOORD_1`…`TEXCOORD_3`).
    pub custom_attributes: bool,
    /// Rotation keys that linear interpolation of their neighbours reproduces within this
    /// angle (degrees) are dropped; 0 keeps every key.
    pub key_tolerance_deg: f32,
    /// Compress vertex, index and animation data with `EXT_meshopt_compression` (then
    /// required by the file).
    pub meshopt: bool,
    /// The level number of `lods[0]` in mesh and node names (`_LOD<k>`): a file holding one
    /// coarser level of a set names it as the set does.
    pub first_lod: usize,
}

impl Default for GltfOptions {
    /// The film target.
    fn default() -> Self {
        Self {
            joints: JointMode::Segment,
            max_joints: None,
            lods: DEFAULT_LODS.to_vec(),
            leaf_joints: true,
            quantize: false,
            custom_attributes: true,
            key_tolerance_deg: 0.0,
            meshopt: false,
            first_lod: 0,
        }
    }
}

/// Joint indices are u16 in `JOINTS_0`.
pub const MAX_JOINTS: usize = 65_535;
/// Largest binary payload written, bytes (1 GiB).
pub const MAX_BIN_BYTES: u64 = 1 << 30;
/// Most levels of detail.
pub const MAX_LODS: usize = 8;

/// Errors exporting glTF.
#[derive(Debug, thiserror::Error)]
pub enum GltfError {
    /// An option is out of range.
    #[error("export option `{field}` = {value}: expected {expected}")]
    Param { field: &'static str, value: String, expected: String },
    /// A level of detail could not be meshed.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// More joints than allowed.
    #[error("the skin would have {joints} joints ({mode}), more than the limit of {limit}{hint}")]
    TooManyJoints { joints: usize, limit: usize, mode: &'static str, hint: &'static str },
    /// The file would be too large.
    #[error(
        "the file would hold {bytes} bytes of data; the limit is {limit} (shorten the clip or use joints per stem)"
    )]
    TooLarge { bytes: u64, limit: u64 },
    /// The clip does not belong to the tree.
    #[error("the clip has {clip} {what} per frame but the tree has {tree}")]
    ClipMismatch { clip: usize, tree: usize, what: &'static str },
    /// Writing failed.
    #[error("{path}: {message}")]
    Io { path: String, message: String },
}

/// What one level of detail holds.
#[derive(Debug, Clone, PartialEq)]
pub struct LodReport {
    /// Its parameters.
    pub lod: Lod,
    /// Triangles (bark + leaves).
    pub triangles: usize,
    /// Vertices (bark + leaves).
    pub vertices: usize,
    /// Leaves kept.
    pub leaves: usize,
    /// Bytes of its geometry in the file.
    pub bytes: usize,
}

/// What was exported.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportReport {
    /// Per level of detail.
    pub lods: Vec<LodReport>,
    /// Skin joints (0 for a static export), leaf joints included.
    pub joints: usize,
    /// Of them, leaf joints.
    pub leaf_joints: usize,
    /// Animation keys per channel (0 for a static export).
    pub frames: usize,
    /// Animation channels.
    pub channels: usize,
    /// Keys written over all channels (fewer than `frames × channels` when reduced).
    pub keys: usize,
    /// Bytes of textures.
    pub texture_bytes: usize,
    /// Bytes of the skin and animation data.
    pub animation_bytes: usize,
    /// Bytes of the binary payload in all.
    pub bin_bytes: usize,
}

/// A built document: the JSON and its binary buffer.
#[derive(Debug)]
pub struct GltfDocument {
    /// The glTF JSON.
    pub root: json::Root,
    /// The one buffer (length a multiple of 4).
    pub bin: Vec<u8>,
    /// Counts and sizes.
    pub report: ExportReport,
}

impl GltfDocument {
    /// Binary glTF (`.glb`).
    pub fn write_glb(&self, w: &mut dyn std::io::Write) -> std::io::Result<()> {
        let json = json::serialize::to_vec(&self.root).map_err(std::io::Error::other)?;
        let glb = gltf::binary::Glb {
            header: gltf::binary::Header { magic: *b"glTF", version: 2, length: 0 },
            json: Cow::Owned(json),
            bin: Some(Cow::Borrowed(&self.bin)),
        };
        glb.to_writer(w).map_err(|e| std::io::Error::other(e.to_string()))
    }

    /// JSON glTF (`.gltf`) with the buffer embedded as a base64 data URI.
    pub fn write_gltf_json(&self, w: &mut dyn std::io::Write) -> std::io::Result<()> {
        use base64::Engine;
        let mut root = self.root.clone();
        root.buffers[0].uri = Some(format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&self.bin)
        ));
        json::serialize::to_writer_pretty(w, &root).map_err(std::io::Error::other)
    }
}

/// Builds the document of `tree` (static when `clip` is `None`).
pub fn build_gltf(tree: &Tree, clip: Option<&Clip>, opts: &GltfOptions) -> Result<GltfDocument, GltfError> {
    if opts.lods.is_empty() || opts.lods.len() > MAX_LODS {
        return Err(GltfError::Param {
            field: "lods",
            value: opts.lods.len().to_string(),
            expected: format!("1 to {MAX_LODS} levels of detail"),
        });
    }
    let n = tree.segments.len();
    if let Some(c) = clip {
        if let Some(bad) = c.joints.iter().chain(&c.acc).find(|f| f.len() != n) {
            return Err(GltfError::ClipMismatch { clip: bad.len(), tree: n, what: "segments" });
        }
        if let Some(bad) = c.leaf_sums.iter().find(|f| !f.is_empty() && f.len() != n) {
            return Err(GltfError::ClipMismatch { clip: bad.len(), tree: n, what: "segments' leaf sums" });
        }
        if c.frames() < 2 {
            return Err(GltfError::Param {
                field: "clip",
                value: format!("{} frames", c.frames()),
                expected: "at least 2 frames".into(),
            });
        }
    }
    if !(opts.key_tolerance_deg.is_finite() && (0.0..=10.0).contains(&opts.key_tolerance_deg)) {
        return Err(GltfError::Param {
            field: "key_tolerance",
            value: opts.key_tolerance_deg.to_string(),
            expected: "0 to 10 degrees".into(),
        });
    }
    if let JointMode::Budget(0) = opts.joints {
        return Err(GltfError::Param { field: "max_joints", value: "0".into(), expected: "at least 1 joint".into() });
    }
    if let Some(bad) = opts.lods.iter().find(|l| !(l.min_radius.is_finite() && l.min_radius >= 0.0)) {
        return Err(GltfError::Param {
            field: "min_radius",
            value: bad.min_radius.to_string(),
            expected: "a stem radius ≥ 0 in m".into(),
        });
    }
    let rig = Rig::new(tree, opts.joints, opts.leaf_joints && clip.is_some());
    let limit = opts.max_joints.unwrap_or(MAX_JOINTS).min(MAX_JOINTS);
    if clip.is_some() && rig.joints() > limit {
        return Err(GltfError::TooManyJoints {
            joints: rig.joints(),
            limit,
            mode: opts.joints.as_str(),
            hint: match (opts.joints, rig.leaf_groups.is_empty()) {
                (JointMode::Segment, true) => " (try joints per stem)",
                (JointMode::Segment, false) => " with leaf joints (try joints per stem, or no leaf joints)",
                (JointMode::Stem, false) => " with leaf joints (try no leaf joints)",
                (JointMode::Stem, true) | (JointMode::Budget(_), _) => "",
            },
        });
    }
    let mut b = Builder { root: json::Root::default(), bin: Vec::new() };
    b.root.asset = json::Asset {
        version: "2.0".into(),
        generator: Some(format!("Sylva {}", env!("CARGO_PKG_VERSION"))),
        copyright: None,
        min_version: None,
        extensions: None,
        extras: Default::default(),
    };
    b.root.buffers.push(json::Buffer {
        byte_length: USize64(0),
        name: None,
        uri: None,
        extensions: None,
        extras: Default::default(),
    });

    // Materials and textures.
    let before = b.bin.len();
    // Bark repeats; leaves clamp to the texture's clear border (their polygons reach just
    // past the square).
    let mut sampler = |wrap: json::texture::WrappingMode| {
        b.root.push(json::texture::Sampler {
            mag_filter: Some(Valid(json::texture::MagFilter::Linear)),
            min_filter: Some(Valid(json::texture::MinFilter::LinearMipmapLinear)),
            wrap_s: Valid(wrap),
            wrap_t: Valid(wrap),
            ..Default::default()
        })
    };
    let (sampler, leaf_sampler) =
        (sampler(json::texture::WrappingMode::Repeat), sampler(json::texture::WrappingMode::ClampToEdge));
    let bark_tex = b.texture("bark", &textures::bark_png(), sampler);
    let bark_normal = b.texture("bark_normal", &textures::bark_normal_png(), sampler);
    let mut leaf_tex = None;
    if opts.lods.iter().any(|l| !l.cards) {
        let tex = b.texture("leaf", &textures::leaf_png(tree.leaf_shape), leaf_sampler);
        leaf_tex = Some((tex, b.texture("leaf_normal", &textures::leaf_normal_png(tree.leaf_shape), leaf_sampler)));
    }
    let mut card_tex = None;
    if opts.lods.iter().any(|l| l.cards) {
        let tex = b.texture("leaf_card", &textures::leaf_card_png(tree.leaf_shape), leaf_sampler);
        let normal = b.texture("leaf_card_normal", &textures::leaf_card_normal_png(tree.leaf_shape), leaf_sampler);
        card_tex = Some((tex, normal));
    }
    let texture_bytes = b.bin.len() - before;
    let material = |name: &str, tex, normal, roughness: f32, leaf: bool| json::Material {
        name: Some(name.into()),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_texture: Some(json::texture::Info {
                index: tex,
                tex_coord: 0,
                extensions: None,
                extras: Default::default(),
            }),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(roughness),
            ..Default::default()
        },
        normal_texture: Some(json::material::NormalTexture {
            index: normal,
            scale: 1.0,
            tex_coord: 0,
            extensions: None,
            extras: Default::default(),
        }),
        alpha_mode: Valid(if leaf { json::material::AlphaMode::Mask } else { json::material::AlphaMode::Opaque }),
        alpha_cutoff: leaf.then_some(json::material::AlphaCutoff(0.5)),
        double_sided: leaf,
        ..Default::default()
    };
    let bark_mat = b.root.push(material("bark", bark_tex, bark_normal, 0.9, false));
    let leaf_mat = leaf_tex.map(|(t, n)| b.root.push(material("leaf", t, n, 0.55, true)));
    let card_mat = card_tex.map(|(t, n)| b.root.push(material("leaf_card", t, n, 0.55, true)));

    // Skin: the armature and its joints.
    let height = tree.height();
    let rest: Vec<Vec3> =
        rig.driver.iter().map(|&s| tree.segments.start[s]).chain(rig.leaf_groups.iter().map(|g| g.pivot)).collect();
    let parent: Vec<u32> = rig.parent.iter().copied().chain(rig.leaf_groups.iter().map(|g| g.parent)).collect();
    let mut scene_nodes = Vec::new();
    let mut skin = None;
    let mut joint_nodes = Vec::new();
    let anim_before = b.bin.len();
    if clip.is_some() {
        let armature = b.root.push(json::Node { name: Some("armature".into()), ..Default::default() });
        scene_nodes.push(armature);
        let first = b.root.nodes.len() as u32;
        joint_nodes = (0..rig.joints() as u32).map(|j| json::Index::new(first + j)).collect();
        for (j, &p) in parent.iter().enumerate() {
            let local = if p == NONE { rest[j] } else { rest[j] - rest[p as usize] };
            b.root.push(json::Node {
                name: Some(rig.name(j)),
                translation: Some(local.to_array()),
                ..Default::default()
            });
        }
        let mut roots = Vec::new();
        let mut children = vec![Vec::new(); rig.joints()];
        for (j, &p) in parent.iter().enumerate() {
            if p == NONE { roots.push(joint_nodes[j]) } else { children[p as usize].push(joint_nodes[j]) }
        }
        b.root.nodes[armature.value()].children = Some(roots);
        for (j, c) in children.into_iter().enumerate() {
            if !c.is_empty() {
                b.root.nodes[joint_nodes[j].value()].children = Some(c);
            }
        }
        let ibm: Vec<f32> = rest.iter().flat_map(|r| Mat4::from_translation(-*r).to_cols_array()).collect();
        let ibm = b.accessor(
            bytemuck::cast_slice(&ibm),
            rest.len(),
            json::accessor::ComponentType::F32,
            json::accessor::Type::Mat4,
            None,
            None,
        );
        skin = Some(b.root.push(json::Skin {
            name: Some("tree".into()),
            inverse_bind_matrices: Some(ibm),
            joints: joint_nodes.clone(),
            skeleton: Some(armature),
            extensions: None,
            extras: Default::default(),
        }));
    }

    // Meshes, one per level of detail.
    let hier = Hierarchy::new(tree);
    let flutter = rig::leaf_flutter(tree);
    let mut lods = Vec::new();
    let mut lod_nodes = Vec::new();
    for (k, lod) in opts.lods.iter().enumerate() {
        let params = MeshParams {
            sides: lod.sides,
            samples: lod.samples,
            leaf_sides: lod.leaf_sides,
            min_stem_radius: lod.min_radius,
            subdivide_min_edge: if lod.subdivide { MeshParams::default().subdivide_min_edge } else { f32::INFINITY },
            ..MeshParams::default()
        };
        let mut layout = MeshLayout::new(tree, params)?;
        layout.thin_leaves(lod.leaf_keep, tree.seed)?;
        let skinned = SkinLayout::new(&layout);
        let before = b.bin.len();
        let mut primitives = Vec::new();
        let fmt = Format { skinned: clip.is_some(), quantize: opts.quantize, custom: opts.custom_attributes };
        let cards = if lod.cards { cards::cards(&layout.leaves) } else { Default::default() };
        let (tube_uv, mesh_leaf_uv) = (layout.tube_uv(), layout.leaf_uv());
        let (vertices, leaf_uv, leaf_skin, indices, leaf_stride, leaf_material) = if lod.cards {
            (&cards.0, &cards.1, &cards.2, &cards.3, cards::CARD_VERTICES, card_mat)
        } else {
            let stride = layout.params.leaf_sides as usize + 1;
            (&skinned.leaf_rest, &mesh_leaf_uv, &skinned.leaf_skin, &layout.leaf_indices, stride, leaf_mat)
        };
        // Bark and leaves side by side: their tangents (MikkTSpace) are most of a level's cost.
        let (bark, leaves) = rayon::join(
            || {
                Geometry::new(&skinned.tube_rest, &tube_uv, &skinned.tube_skin, &layout.tube_indices, |_, s| {
                    hier.bark(tree, s.bone0 as usize)
                })
            },
            || {
                (!layout.leaves.is_empty()).then(|| {
                    let mut g = Geometry::new(vertices, leaf_uv, leaf_skin, indices, |v, _| {
                        hier.leaf(tree, &layout.leaves[v / leaf_stride])
                    });
                    g.flutter = (0..vertices.len())
                        .map(|v| {
                            flutter.get(layout.leaves[v / leaf_stride].index as usize).copied().unwrap_or_default()
                        })
                        .collect();
                    g
                })
            },
        );
        primitives.push(b.primitive(&bark, &rig, fmt, bark_mat));
        // A level's leaf material is made whenever a level uses that kind of leaf.
        if let (Some(leaves), Some(mat)) = (leaves, leaf_material) {
            primitives.push(b.primitive(&leaves, &rig, fmt, mat));
        }
        let name = format!("{}_LOD{}", tree.name, k + opts.first_lod);
        let mesh = b.root.push(json::Mesh {
            name: Some(name.clone()),
            primitives,
            weights: None,
            extensions: None,
            extras: Default::default(),
        });
        lod_nodes.push(b.root.push(json::Node { name: Some(name), mesh: Some(mesh), skin, ..Default::default() }));
        lods.push(LodReport {
            lod: *lod,
            triangles: (layout.tube_indices.len() + indices.len()) / 3,
            vertices: layout.tube_vertex_count() + if lod.cards { vertices.len() } else { layout.leaf_vertex_count() },
            leaves: layout.leaves.len(),
            bytes: b.bin.len() - before,
        });
        if b.bin.len() as u64 > MAX_BIN_BYTES {
            return Err(GltfError::TooLarge { bytes: b.bin.len() as u64, limit: MAX_BIN_BYTES });
        }
    }

    // Only the finest level is in the scene; `MSFT_lod` names the coarser ones, with the
    // screen coverage below which each gives way to the next.
    scene_nodes.push(lod_nodes[0]);
    if lod_nodes.len() > 1 {
        let ids: Vec<u32> = lod_nodes[1..].iter().map(|n| n.value() as u32).collect();
        let node = &mut b.root.nodes[lod_nodes[0].value()];
        let mut ext = json::extensions::scene::Node::default();
        ext.others.insert("MSFT_lod".into(), serde_json::json!({ "ids": ids }));
        node.extensions = Some(ext);
        let coverage: Vec<f32> = (0..lod_nodes.len()).map(|k| lod_coverage(k + opts.first_lod)).collect();
        node.extras = Some(
            serde_json::value::to_raw_value(&serde_json::json!({ "MSFT_screencoverage": coverage }))
                .map_err(|e| GltfError::Io { path: "extras".into(), message: e.to_string() })?,
        );
        b.root.extensions_used.push("MSFT_lod".into());
    }
    if opts.quantize {
        b.root.extensions_used.push("KHR_mesh_quantization".into());
        b.root.extensions_required.push("KHR_mesh_quantization".into());
    }

    // Animation.
    let anim_mesh_bytes: usize = lods.iter().map(|l| l.bytes).sum();
    let mut channels = 0;
    let mut keys = 0;
    if let Some(c) = clip {
        let (samplers, chans) = b.animation(tree, c, &rig, &joint_nodes, height, opts.key_tolerance_deg)?;
        channels = chans.len();
        keys = samplers.iter().map(|s| b.root.accessors[s.input.value()].count.0 as usize).sum();
        b.root.push(json::Animation {
            name: Some(if c.looped { "wind_loop" } else { "wind" }.into()),
            channels: chans,
            samplers,
            extensions: None,
            extras: Default::default(),
        });
    }
    let animation_bytes = b.bin.len() - anim_before - anim_mesh_bytes;
    let scene = b.root.push(json::Scene {
        name: Some(tree.name.clone()),
        nodes: scene_nodes,
        extensions: None,
        extras: Default::default(),
    });
    b.root.scene = Some(scene);
    while b.bin.len() % 4 != 0 {
        b.bin.push(0);
    }
    b.root.buffers[0].byte_length = USize64(b.bin.len() as u64);
    if opts.meshopt {
        meshopt::compress(&mut b.root, &mut b.bin);
    }
    let report = ExportReport {
        lods,
        joints: if clip.is_some() { rig.joints() } else { 0 },
        leaf_joints: rig.leaf_groups.len(),
        frames: clip.map_or(0, |c| c.frames()),
        channels,
        keys,
        texture_bytes,
        animation_bytes,
        bin_bytes: b.bin.len(),
    };
    Ok(GltfDocument { root: b.root, bin: b.bin, report })
}

/// Screen coverage (the share of the screen's height the tree's bounds fill) down to which
/// level `k` is drawn: ½, then a third of the level before (`MSFT_screencoverage`).
pub fn lod_coverage(k: usize) -> f32 {
    0.5 / 3f32.powi(k as i32)
}

/// Builds and writes `path` atomically: `.glb` binary, `.gltf` JSON with data URIs.
pub fn write_gltf(
    tree: &Tree,
    clip: Option<&Clip>,
    opts: &GltfOptions,
    path: &Path,
) -> Result<ExportReport, GltfError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let binary = match ext.as_deref() {
        Some("glb") => true,
        Some("gltf") => false,
        _ => {
            return Err(GltfError::Param {
                field: "out",
                value: path.display().to_string(),
                expected: "a file name ending in .glb or .gltf".into(),
            });
        }
    };
    let doc = build_gltf(tree, clip, opts)?;
    write_atomic(path, |w| if binary { doc.write_glb(w) } else { doc.write_gltf_json(w) })
        .map_err(|e| GltfError::Io { path: path.display().to_string(), message: e.to_string() })?;
    Ok(doc.report)
}
