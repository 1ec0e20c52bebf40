//! Writing glTF's buffers, views and accessors: one binary buffer grown as arrays are
//! added, each array its own view and accessor.

use super::*;

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
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64(bytes.len() as u64),
            byte_offset: Some(USize64(offset as u64)),
            byte_stride: None,
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
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64(count as u64),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            type_: Valid(ty),
            min,
            max,
            name: None,
            normalized: false,
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
        skinned: bool,
        material: json::Index<json::Material>,
    ) -> json::mesh::Primitive {
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
        let normals: Vec<f32> = v.iter().flat_map(|x| Vec3::from_array(x.normal).normalize().to_array()).collect();
        attributes.insert(Valid(Semantic::Normals), self.floats(&normals, V3, true));
        let tangents: Vec<f32> = g.tangents.iter().flatten().copied().collect();
        attributes.insert(Valid(Semantic::Tangents), self.floats(&tangents, Vec4, true));
        let uv: Vec<f32> = v.iter().flat_map(|x| [x.u, x.v]).collect();
        attributes.insert(Valid(Semantic::TexCoords(0)), self.floats(&uv, Vec2, true));
        if skinned {
            let (joints, weights): (Vec<[u16; 4]>, Vec<[f32; 4]>) =
                g.skin.iter().zip(v).map(|(s, x)| rig.bind(s, x.v)).unzip();
            let j = self.accessor(
                bytemuck::cast_slice(&joints),
                joints.len(),
                json::accessor::ComponentType::U16,
                Vec4,
                Some(json::buffer::Target::ArrayBuffer),
                None,
            );
            attributes.insert(Valid(Semantic::Joints(0)), j);
            let w: Vec<f32> = weights.iter().flatten().copied().collect();
            attributes.insert(Valid(Semantic::Weights(0)), self.floats(&w, Vec4, true));
        }
        let e = &g.elements;
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
        let indices = self.accessor(
            bytemuck::cast_slice(g.indices),
            g.indices.len(),
            json::accessor::ComponentType::U32,
            Scalar,
            Some(json::buffer::Target::ElementArrayBuffer),
            None,
        );
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
                rot[k * frames + f] = rig::group_rotation(group, clip.leaves.get(f).map_or(&[], Vec::as_slice));
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
            let mut channel = |b: &mut Builder, data: Vec<f32>, ty, path| {
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
                let data = r.iter().flat_map(|q| q.to_array()).collect();
                channel(self, data, json::accessor::Type::Vec4, json::animation::Property::Rotation);
            }
            if shifts {
                let data = o.iter().flat_map(|x| x.to_array()).collect();
                channel(self, data, json::accessor::Type::Vec3, json::animation::Property::Translation);
            }
        }
        Ok((samplers, channels))
    }
}
