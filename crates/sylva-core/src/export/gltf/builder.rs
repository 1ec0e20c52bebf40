//! Writing glTF's buffers, views and accessors: one binary buffer grown as arrays are
//! added, each array its own view and accessor.

use super::*;

/// How a primitive's vertex data is written.
#[derive(Debug, Clone, Copy)]
pub(super) struct Format {
    /// With `JOINTS_0` and `WEIGHTS_0`.
    pub(super) skinned: bool,
    /// Compact: `KHR_mesh_quantization` normals and tangents (i8), texture coordinates in
    /// 0…1 as u16, the axis as i16, joints u8 (≤ 256 joints) and weights u8, normalised.
    pub(super) quantize: bool,
    /// The custom float attributes `_PIVOT`, … as well.
    pub(super) custom: bool,
}

/// Largest phase packed beside the depth in `TEXCOORD_1.x`, so that `floor` gives the depth.
pub const PHASE_MAX: f32 = 0.999;

/// Normalised i8 of `x` in −1…1 (glTF's `round(x × 127)`).
pub(super) fn snorm8(x: f32) -> i8 {
    (x.clamp(-1.0, 1.0) * 127.0).round() as i8
}

/// Normalised i16 of `x` in −1…1.
pub(super) fn snorm16(x: f32) -> i16 {
    (x.clamp(-1.0, 1.0) * 32767.0).round() as i16
}

/// Normalised u16 of `x` in 0…1.
pub(super) fn unorm16(x: f32) -> u16 {
    (x.clamp(0.0, 1.0) * 65535.0).round() as u16
}

/// Weights as normalised u8 summing to exactly 255 (the largest takes the rounding).
pub(super) fn weights_u8(w: [f32; 4]) -> [u8; 4] {
    let mut q = w.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as i32);
    let big = (0..4).max_by(|&a, &b| w[a].total_cmp(&w[b]).then(b.cmp(&a))).unwrap_or(0);
    q[big] += 255 - q.iter().sum::<i32>();
    q.map(|x| x.clamp(0, 255) as u8)
}

/// Octahedral encoding of a unit vector in −1…1² (Cigolle et al. 2014): `x`, `z` of its
/// projection onto the octahedron `|x|+|y|+|z| = 1`, the lower half folded out.
pub fn octahedral(n: Vec3) -> [f32; 2] {
    let n = n / (n.x.abs() + n.y.abs() + n.z.abs()).max(1e-20);
    if n.y >= 0.0 { [n.x, n.z] } else { [(1.0 - n.z.abs()) * n.x.signum(), (1.0 - n.x.abs()) * n.z.signum()] }
}

/// The unit vector of an octahedral code ([`octahedral`]'s inverse).
pub fn octahedral_decode(e: [f32; 2]) -> Vec3 {
    let (x, z) = (e[0], e[1]);
    let y = 1.0 - x.abs() - z.abs();
    let (x, z) = if y < 0.0 { ((1.0 - z.abs()) * x.signum(), (1.0 - x.abs()) * z.signum()) } else { (x, z) };
    Vec3::new(x, y, z).normalize()
}

pub(super) struct Builder {
    pub(super) root: json::Root,
    pub(super) bin: Vec<u8>,
}

impl Builder {
    pub(super) fn view(
        &mut self,
        bytes: &[u8],
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        self.view_strided(bytes, target, None)
    }

    fn view_strided(
        &mut self,
        bytes: &[u8],
        target: Option<json::buffer::Target>,
        stride: Option<usize>,
    ) -> json::Index<json::buffer::View> {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64(bytes.len() as u64),
            byte_offset: Some(USize64(offset as u64)),
            byte_stride: stride.map(json::buffer::Stride),
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    pub(super) fn accessor(
        &mut self,
        bytes: &[u8],
        count: usize,
        component: json::accessor::ComponentType,
        ty: json::accessor::Type,
        target: Option<json::buffer::Target>,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    ) -> json::Index<json::Accessor> {
        let view = self.view(bytes, target);
        let (min, max) = match bounds {
            Some((lo, hi)) => (Some(json::Value::from(lo)), Some(json::Value::from(hi))),
            None => (None, None),
        };
        self.push_accessor(view, count, component, ty, (min, max), false)
    }

    /// An integer vertex attribute of `T` (i8, u8, i16 or u16), `n` components per element,
    /// each element padded to 4 bytes (glTF's vertex alignment).
    pub(super) fn ints<T: bytemuck::Pod + Default>(
        &mut self,
        data: &[T],
        ty: json::accessor::Type,
        component: json::accessor::ComponentType,
        normalized: bool,
    ) -> json::Index<json::Accessor> {
        let n = ty.multiplicity();
        let size = std::mem::size_of::<T>() * n;
        let stride = size.next_multiple_of(4);
        let per = stride / std::mem::size_of::<T>();
        let count = data.len() / n;
        let mut padded = vec![T::default(); count * per];
        for (out, x) in padded.chunks_exact_mut(per).zip(data.chunks_exact(n)) {
            out[..n].copy_from_slice(x);
        }
        let target = Some(json::buffer::Target::ArrayBuffer);
        let view = self.view_strided(bytemuck::cast_slice(&padded), target, (stride != size).then_some(stride));
        self.push_accessor(view, count, component, ty, (None, None), normalized)
    }

    fn push_accessor(
        &mut self,
        view: json::Index<json::buffer::View>,
        count: usize,
        component: json::accessor::ComponentType,
        ty: json::accessor::Type,
        (min, max): (Option<json::Value>, Option<json::Value>),
        normalized: bool,
    ) -> json::Index<json::Accessor> {
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64(count as u64),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            type_: Valid(ty),
            min,
            max,
            name: None,
            normalized,
            sparse: None,
            extensions: None,
            extras: Default::default(),
        })
    }

    pub(super) fn floats(
        &mut self,
        data: &[f32],
        ty: json::accessor::Type,
        target: bool,
    ) -> json::Index<json::Accessor> {
        let count = data.len() / ty.multiplicity();
        let target = target.then_some(json::buffer::Target::ArrayBuffer);
        self.accessor(bytemuck::cast_slice(data), count, json::accessor::ComponentType::F32, ty, target, None)
    }

    pub(super) fn texture(
        &mut self,
        name: &str,
        png: &[u8],
        sampler: json::Index<json::texture::Sampler>,
    ) -> json::Index<json::Texture> {
        let view = self.view(png, None);
        let image = self.root.push(json::Image {
            buffer_view: Some(view),
            mime_type: Some(json::image::MimeType("image/png".into())),
            uri: None,
            name: Some(name.into()),
            extensions: None,
            extras: Default::default(),
        });
        self.root.push(json::Texture {
            name: Some(name.into()),
            sampler: Some(sampler),
            source: image,
            extensions: None,
            extras: Default::default(),
        })
    }

    pub(super) fn primitive(
        &mut self,
        g: &Geometry<'_>,
        rig: &Rig,
        fmt: Format,
        material: json::Index<json::Material>,
    ) -> json::mesh::Primitive {
        use json::accessor::ComponentType::{I8, I16, U8, U16, U32};
        use json::accessor::Type::{Scalar, Vec2, Vec3 as V3, Vec4};
        use json::mesh::Semantic;
        let v = g.vertices;
        let pos: Vec<f32> = v.iter().flat_map(|x| x.position).collect();
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for x in v {
            for k in 0..3 {
                lo[k] = lo[k].min(x.position[k]);
                hi[k] = hi[k].max(x.position[k]);
            }
        }
        let mut attributes = std::collections::BTreeMap::new();
        let position = self.accessor(
            bytemuck::cast_slice(&pos),
            v.len(),
            json::accessor::ComponentType::F32,
            V3,
            Some(json::buffer::Target::ArrayBuffer),
            Some((lo.to_vec(), hi.to_vec())),
        );
        attributes.insert(Valid(Semantic::Positions), position);
        let normals: Vec<Vec3> = v.iter().map(|x| x.normal()).collect();
        let (normal, tangent) = if fmt.quantize {
            let n: Vec<i8> = normals.iter().flat_map(|n| n.to_array().map(snorm8)).collect();
            let t: Vec<i8> = g.tangents.iter().flat_map(|t| t.map(snorm8)).collect();
            (self.ints(&n, V3, I8, true), self.ints(&t, Vec4, I8, true))
        } else {
            let n: Vec<f32> = normals.iter().flat_map(|n| n.to_array()).collect();
            let t: Vec<f32> = g.tangents.iter().flatten().copied().collect();
            (self.floats(&n, V3, true), self.floats(&t, Vec4, true))
        };
        attributes.insert(Valid(Semantic::Normals), normal);
        attributes.insert(Valid(Semantic::Tangents), tangent);
        let in_unit = g.uv.iter().all(|x| (0.0..=1.0).contains(&x[0]) && (0.0..=1.0).contains(&x[1]));
        let uv = if fmt.quantize && in_unit {
            let uv: Vec<u16> = g.uv.iter().flat_map(|x| x.map(unorm16)).collect();
            self.ints(&uv, Vec2, U16, true)
        } else {
            let uv: Vec<f32> = g.uv.iter().flatten().copied().collect();
            self.floats(&uv, Vec2, true)
        };
        attributes.insert(Valid(Semantic::TexCoords(0)), uv);
        if fmt.skinned {
            let (joints, weights): (Vec<[u16; 4]>, Vec<[f32; 4]>) =
                g.skin.iter().zip(g.uv).map(|(s, x)| rig.bind(s, x[1])).unzip();
            let (j, w) = if fmt.quantize {
                let weights: Vec<[u8; 4]> = weights.iter().map(|w| weights_u8(*w)).collect();
                // A weight that rounds to zero leaves its joint unused: glTF wants it 0 too.
                let joints: Vec<[u16; 4]> = joints
                    .iter()
                    .zip(&weights)
                    .map(|(j, w)| std::array::from_fn(|k| if w[k] == 0 { 0 } else { j[k] }))
                    .collect();
                let j = if rig.joints() <= 256 {
                    let j: Vec<u8> = joints.iter().flatten().map(|&j| j as u8).collect();
                    self.ints(&j, Vec4, U8, false)
                } else {
                    self.ints(&joints.concat(), Vec4, U16, false)
                };
                (j, self.ints(&weights.concat(), Vec4, U8, true))
            } else {
                let w: Vec<f32> = weights.iter().flatten().copied().collect();
                (self.ints(&joints.concat(), Vec4, U16, false), self.floats(&w, Vec4, true))
            };
            attributes.insert(Valid(Semantic::Joints(0)), j);
            attributes.insert(Valid(Semantic::Weights(0)), w);
        }
        // The hierarchy packed in standard channels (see "Hierarchy data" in the module
        // documentation): importers keep texture coordinates (`TEXCOORD_1` at least).
        let e = &g.elements;
        let t1: Vec<f32> = e.iter().flat_map(|x| [x.depth + x.phase.min(PHASE_MAX), x.pivot.y]).collect();
        attributes.insert(Valid(Semantic::TexCoords(1)), self.floats(&t1, Vec2, true));
        let t2: Vec<f32> = e.iter().flat_map(|x| [x.pivot.x, x.pivot.z]).collect();
        attributes.insert(Valid(Semantic::TexCoords(2)), self.floats(&t2, Vec2, true));
        let oct: Vec<[f32; 2]> = e.iter().map(|x| octahedral(x.axis)).collect();
        let t3 = if fmt.quantize {
            let t3: Vec<i16> = oct.iter().flat_map(|o| o.map(snorm16)).collect();
            self.ints(&t3, Vec2, I16, true)
        } else {
            self.floats(&oct.concat(), Vec2, true)
        };
        attributes.insert(Valid(Semantic::TexCoords(3)), t3);
        if fmt.custom {
            let pivot: Vec<f32> = e.iter().flat_map(|x| x.pivot.to_array()).collect();
            attributes.insert(Valid(Semantic::Extras("PIVOT".into())), self.floats(&pivot, V3, true));
            let axis: Vec<f32> = e.iter().flat_map(|x| x.axis.to_array()).collect();
            attributes.insert(Valid(Semantic::Extras("BRANCH_AXIS".into())), self.floats(&axis, V3, true));
            let depth: Vec<f32> = e.iter().map(|x| x.depth).collect();
            attributes.insert(Valid(Semantic::Extras("HIERARCHY_DEPTH".into())), self.floats(&depth, Scalar, true));
            let parent: Vec<f32> = e.iter().flat_map(|x| x.parent_pivot.to_array()).collect();
            attributes.insert(Valid(Semantic::Extras("PARENT_PIVOT".into())), self.floats(&parent, V3, true));
            let phase: Vec<f32> = e.iter().map(|x| x.phase).collect();
            attributes.insert(Valid(Semantic::Extras("PHASE".into())), self.floats(&phase, Scalar, true));
            if !g.flutter.is_empty() {
                let flutter: Vec<f32> = g.flutter.iter().flatten().copied().collect();
                attributes.insert(Valid(Semantic::Extras("LEAF_FLUTTER".into())), self.floats(&flutter, V3, true));
            }
        }
        let target = Some(json::buffer::Target::ElementArrayBuffer);
        let indices = if v.len() <= u16::MAX as usize {
            let short: Vec<u16> = g.indices.iter().map(|&i| i as u16).collect();
            self.accessor(bytemuck::cast_slice(&short), short.len(), U16, Scalar, target, None)
        } else {
            self.accessor(bytemuck::cast_slice(g.indices), g.indices.len(), U32, Scalar, target, None)
        };
        json::mesh::Primitive {
            attributes,
            indices: Some(indices),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
            extensions: None,
            extras: Default::default(),
        }
    }

    /// Samplers and channels of the clip: local rotation (and, where it changes,
    /// translation) of every skeleton joint that moves, and the rotation of every leaf joint
    /// that turns.
    pub(super) fn animation(
        &mut self,
        tree: &Tree,
        clip: &Clip,
        rig: &Rig,
        nodes: &[json::Index<json::Node>],
        height: f32,
        tolerance_deg: f32,
    ) -> Result<(Vec<json::animation::Sampler>, Vec<json::animation::Channel>), GltfError> {
        let frames = clip.frames();
        let joints = rig.driver.len();
        let bytes = frames as u64 * rig.joints() as u64 * 28;
        if self.bin.len() as u64 + bytes > MAX_BIN_BYTES {
            return Err(GltfError::TooLarge { bytes: self.bin.len() as u64 + bytes, limit: MAX_BIN_BYTES });
        }
        let s = &tree.segments;
        let times: Vec<f32> = (0..frames).map(|k| k as f32 / clip.fps).collect();
        let input = self.accessor(
            bytemuck::cast_slice(&times),
            frames,
            json::accessor::ComponentType::F32,
            json::accessor::Type::Scalar,
            None,
            Some((vec![0.0], vec![times[frames - 1]])),
        );
        // Local transforms per frame, joint-major; leaf joints after the skeleton's, their
        // offsets from their parents constant.
        let all = rig.joints();
        let mut rot = vec![Quat::IDENTITY; frames * all];
        let mut off = vec![Vec3::ZERO; frames * all];
        for f in 0..frames {
            let (j, d) = (&clip.joints[f], &clip.acc[f]);
            for (k, &s) in rig.driver.iter().enumerate() {
                let (ws, wp) = (Quat::from_array(d[s]), Vec3::from_slice(&j[s][..3]));
                let (r, o) = match rig.parent[k] {
                    NONE => (ws, wp),
                    p => {
                        let ps = rig.driver[p as usize];
                        let inv = Quat::from_array(d[ps]).conjugate();
                        (inv * ws, inv * (wp - Vec3::from_slice(&j[ps][..3])))
                    }
                };
                rot[k * frames + f] = r.normalize();
                off[k * frames + f] = o;
            }
            for (g, group) in rig.leaf_groups.iter().enumerate() {
                let k = joints + g;
                rot[k * frames + f] = rig::group_rotation(group, clip.leaf_sums.get(f).map_or(&[], Vec::as_slice));
                off[k * frames + f] = group.pivot - s.start[rig.driver[group.parent as usize]];
            }
        }
        let mut samplers = Vec::new();
        let mut channels = Vec::new();
        for k in 0..all {
            let rest = match k.checked_sub(joints) {
                Some(_) => off[k * frames],
                None => match rig.parent[k] {
                    NONE => s.start[rig.driver[k]],
                    p => s.start[rig.driver[k]] - s.start[rig.driver[p as usize]],
                },
            };
            let r = &mut rot[k * frames..(k + 1) * frames];
            for f in 1..frames {
                if r[f].dot(r[f - 1]) < 0.0 {
                    r[f] = -r[f];
                }
            }
            // |xyz| = sin(angle / 2): exact for small angles, where f32 `acos` is not.
            let moves = r.iter().any(|q| q.xyz().length() > 1e-7);
            let o = &off[k * frames..(k + 1) * frames];
            let shifts = o.iter().any(|x| (*x - rest).length() > 1e-6 * height);
            let mut channel = |b: &mut Builder, input, data: Vec<f32>, ty, path| {
                let output = b.floats(&data, ty, false);
                samplers.push(json::animation::Sampler {
                    input,
                    output,
                    interpolation: Valid(json::animation::Interpolation::Linear),
                    extensions: None,
                    extras: Default::default(),
                });
                channels.push(json::animation::Channel {
                    sampler: json::Index::new(samplers.len() as u32 - 1),
                    target: json::animation::Target {
                        node: nodes[k],
                        path: Valid(path),
                        extensions: None,
                        extras: Default::default(),
                    },
                    extensions: None,
                    extras: Default::default(),
                });
            };
            if moves {
                let keep = reduce_keys(r, tolerance_deg.to_radians());
                let (input, data) = if keep.len() == frames {
                    (input, r.iter().flat_map(|q| q.to_array()).collect())
                } else {
                    let t: Vec<f32> = keep.iter().map(|&f| times[f]).collect();
                    let bounds = Some((vec![0.0], vec![times[frames - 1]]));
                    let scalar = json::accessor::Type::Scalar;
                    let input = self.accessor(
                        bytemuck::cast_slice(&t),
                        t.len(),
                        json::accessor::ComponentType::F32,
                        scalar,
                        None,
                        bounds,
                    );
                    (input, keep.iter().flat_map(|&f| r[f].to_array()).collect())
                };
                channel(self, input, data, json::accessor::Type::Vec4, json::animation::Property::Rotation);
            }
            if shifts {
                let data = o.iter().flat_map(|x| x.to_array()).collect();
                channel(self, input, data, json::accessor::Type::Vec3, json::animation::Property::Translation);
            }
        }
        Ok((samplers, channels))
    }
}

/// The keys of `r` (one per frame, consecutive keys in one hemisphere) that keep every
/// dropped key within `tolerance` (rad) of the slerp between the kept keys around it:
/// greedily, each run as long as it stays within. The first and last keys are always kept;
/// a tolerance of 0 keeps every key.
pub fn reduce_keys(r: &[Quat], tolerance: f32) -> Vec<usize> {
    let n = r.len();
    if tolerance <= 0.0 || n <= 2 {
        return (0..n).collect();
    }
    // |xyz| of the difference is sin(angle / 2): exact for small angles.
    let limit = (0.5 * tolerance).sin();
    let fits = |a: usize, b: usize| {
        (a + 1..b).all(|k| {
            let q = r[a].slerp(r[b], (k - a) as f32 / (b - a) as f32);
            (r[k].conjugate() * q).xyz().length() <= limit
        })
    };
    let mut keep = vec![0];
    let mut a = 0;
    while a + 1 < n {
        let mut b = a + 1;
        while b + 1 < n && fits(a, b + 1) {
            b += 1;
        }
        keep.push(b);
        a = b;
    }
    keep
}
