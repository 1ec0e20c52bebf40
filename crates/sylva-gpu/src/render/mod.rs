//! The offscreen renderer: sky, a ground plane, bark and leaves lit by a sun with a shadow
//! map, depth-tested and multisampled, many trees by instancing.
//!
//! It draws the vertex buffers the mesh kernels write ([`crate::mesh::GpuMesh`]) as they
//! are — no CPU round trip per frame — once per instance, with a per-instance transform and
//! tint. A frame is: shadow pass (depth from the sun, orthographic, fitted to the scene's
//! bounds) → main pass (sky, ground, bark, two-sided leaves into a 4× MSAA target) →
//! resolve → read back as RGBA8. The render target is a texture, so an interactive window
//! can reuse every pipeline with its surface's format instead.

use crate::{GpuContext, GpuError};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

/// The renderer's WGSL (validated by naga in the tests).
pub const RENDER_WGSL: &str =
    concat!(include_str!("leaf_shape.wgsl"), include_str!("../mesh/vertex.wgsl"), include_str!("render.wgsl"));

const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Image size and quality.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderSettings {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel (4 when the adapter supports it, else 1).
    pub msaa: u32,
    /// Shadow map resolution (square).
    pub shadow_size: u32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self { width: 960, height: 540, msaa: 4, shadow_size: 2048 }
    }
}

/// Largest image side accepted.
pub const MAX_SIDE: u32 = 8192;

/// A perspective camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Eye position, m.
    pub eye: Vec3,
    /// Point looked at, m.
    pub target: Vec3,
    /// Vertical field of view, degrees.
    pub fov_y_deg: f32,
}

impl Camera {
    /// View-projection matrix for an image of `aspect` = width / height (depth 0…1).
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        let dist = (self.target - self.eye).length().max(1e-3);
        let proj = Mat4::perspective_rh(self.fov_y_deg.to_radians(), aspect, (dist * 0.01).max(0.05), dist * 40.0);
        proj * Mat4::look_at_rh(self.eye, self.target, Vec3::Y)
    }
}

/// Sun, sky and ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lighting {
    /// Unit direction towards the sun.
    pub sun_direction: Vec3,
    /// Sun colour (linear).
    pub sun_colour: Vec3,
    /// Sun intensity multiplier.
    pub sun_intensity: f32,
    /// Sky colour overhead (linear).
    pub sky_zenith: Vec3,
    /// Sky colour at the horizon (linear), also the fog colour.
    pub sky_horizon: Vec3,
    /// Ground albedo (linear).
    pub ground: Vec3,
    /// Half the ground's side, m.
    pub ground_half_size: f32,
    /// Distance at which fog reaches 63 %, m.
    pub fog_distance: f32,
}

impl Default for Lighting {
    fn default() -> Self {
        Self {
            sun_direction: Vec3::new(0.45, 0.75, 0.35).normalize(),
            sun_colour: Vec3::new(1.0, 0.95, 0.86),
            sun_intensity: 2.6,
            sky_zenith: Vec3::new(0.20, 0.38, 0.72),
            sky_horizon: Vec3::new(0.62, 0.72, 0.84),
            ground: Vec3::new(0.16, 0.24, 0.08),
            ground_half_size: 150.0,
            fog_distance: 260.0,
        }
    }
}

/// One instance of a tree mesh: a transform (rigid + uniform scale) and a leaf tint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instance {
    /// Model matrix.
    pub transform: Mat4,
    /// Leaf colour (linear); bark takes a hint of it.
    pub tint: Vec3,
    /// The outline the leaves are cut to (the tree's [`sylva_core::model::LeafShape`]).
    pub leaf_shape: sylva_core::model::LeafShape,
}

/// GPU twin of [`Instance`], 80 bytes: four matrix columns and the tint (vertex attributes
/// 3–7 of `render.wgsl`, the third vertex buffer).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawInstance {
    /// Matrix columns.
    pub model: [[f32; 4]; 4],
    /// Tint (rgb) and the leaf shape's index (w).
    pub tint: [f32; 4],
}

/// Per-frame constants, the twin of `struct Globals` in `render.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawGlobals {
    /// Camera view-projection.
    pub view_proj: [[f32; 4]; 4],
    /// Its inverse (sky rays).
    pub inv_view_proj: [[f32; 4]; 4],
    /// Sun view-projection (shadow map).
    pub sun_view_proj: [[f32; 4]; 4],
    /// Eye position.
    pub eye: [f32; 4],
    /// Towards the sun, w = intensity.
    pub sun_dir: [f32; 4],
    /// Sun colour.
    pub sun_colour: [f32; 4],
    /// Sky overhead.
    pub sky_zenith: [f32; 4],
    /// Sky at the horizon.
    pub sky_horizon: [f32; 4],
    /// Ground albedo, w = half size.
    pub ground: [f32; 4],
    /// x = shadow texel, y = fog distance.
    pub params: [f32; 4],
}

/// Vertex and index buffers of one material.
#[derive(Debug, Clone, Copy)]
pub struct MeshBuffers<'a> {
    /// Vertices ([`sylva_core::mesh::RawVertex`], 16 bytes: `Float32x3` position, `Snorm16x2`
    /// octahedral normal), written by a mesh or skinning kernel.
    pub vertices: &'a wgpu::Buffer,
    /// Texture coordinates ([`sylva_core::mesh::Uv`], `Float32x2`), one per vertex of one
    /// instance, static.
    pub uv: &'a wgpu::Buffer,
    /// Triangle indices.
    pub indices: &'a wgpu::Buffer,
    /// Number of indices.
    pub index_count: u32,
    /// 0: every instance draws the same vertices; n: instance k draws vertices `k × n ..`
    /// (skinned instances, each with its own pose).
    pub per_instance_vertices: u32,
}

/// A tree drawn once per instance: bark and leaves.
#[derive(Debug, Clone, Copy)]
pub struct DrawItem<'a> {
    /// Bark.
    pub bark: MeshBuffers<'a>,
    /// Leaves.
    pub leaves: MeshBuffers<'a>,
    /// Instance transforms (from [`Renderer::instances`]).
    pub instances: &'a wgpu::Buffer,
    /// The first transform of `instances` this item draws.
    pub first_instance: u32,
    /// How many.
    pub instance_count: u32,
}

/// Pipelines and targets for one image size.
#[derive(Debug)]
pub struct Renderer {
    settings: RenderSettings,
    globals: wgpu::Buffer,
    globals_bind: wgpu::BindGroup,
    shadow_bind: wgpu::BindGroup,
    sky: wgpu::RenderPipeline,
    ground: wgpu::RenderPipeline,
    bark: wgpu::RenderPipeline,
    leaf: wgpu::RenderPipeline,
    shadow: wgpu::RenderPipeline,
    shadow_leaf: wgpu::RenderPipeline,
    color: wgpu::TextureView,
    resolve: wgpu::Texture,
    depth: wgpu::TextureView,
    shadow_view: wgpu::TextureView,
    readback: wgpu::Buffer,
    padded_row: u32,
}

/// Errors of the renderer.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A GPU failure.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// Bad settings.
    #[error("render setting `{field}` = {value}: expected {expected}")]
    Setting { field: &'static str, value: String, expected: &'static str },
}

fn vertex_layouts() -> [Option<wgpu::VertexBufferLayout<'static>>; 3] {
    // sylva_core::mesh::RawVertex: position, octahedral normal; then the static uv stream.
    const VERTEX: [wgpu::VertexAttribute; 2] = wgpu::vertex_attr_array![0 => Float32x3, 1 => Snorm16x2];
    const UV: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![2 => Float32x2];
    const INSTANCE: [wgpu::VertexAttribute; 5] =
        wgpu::vertex_attr_array![3 => Float32x4, 4 => Float32x4, 5 => Float32x4, 6 => Float32x4, 7 => Float32x4];
    [
        Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<sylva_core::mesh::RawVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &VERTEX,
        }),
        Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<sylva_core::mesh::Uv>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &UV,
        }),
        Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<RawInstance>() as u64,
            step_mode: wgpu::VertexStepMode::Instance,
            attributes: &INSTANCE,
        }),
    ]
}

impl Renderer {
    /// Builds pipelines and targets for `settings` (MSAA lowered to 1 where unsupported).
    pub fn new(ctx: &GpuContext, mut settings: RenderSettings) -> Result<Self, RenderError> {
        let max = ctx.device.limits().max_texture_dimension_2d.min(MAX_SIDE);
        for (field, v) in [("width", settings.width), ("height", settings.height)] {
            if v == 0 || v > max {
                return Err(RenderError::Setting { field, value: v.to_string(), expected: "1 to 8192 pixels" });
            }
        }
        if !(256..=max).contains(&settings.shadow_size) {
            return Err(RenderError::Setting {
                field: "shadow_size",
                value: settings.shadow_size.to_string(),
                expected: "256 to 8192",
            });
        }
        let flags = ctx.adapter.get_texture_format_features(COLOR_FORMAT).flags;
        let depth_flags = ctx.adapter.get_texture_format_features(DEPTH_FORMAT).flags;
        if settings.msaa > 1
            && !(flags.sample_count_supported(settings.msaa) && depth_flags.sample_count_supported(settings.msaa))
        {
            settings.msaa = 1;
        }
        let device = &ctx.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("render"),
            source: wgpu::ShaderSource::Wgsl(RENDER_WGSL.into()),
        });
        let globals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("globals"),
            size: std::mem::size_of::<RawGlobals>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let g0 = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("globals"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let g1 = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow map"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                    count: None,
                },
            ],
        });
        let shadow_tex = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow map"),
            size: wgpu::Extent3d {
                width: settings.shadow_size,
                height: settings.shadow_size,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let shadow_view = shadow_tex.create_view(&Default::default());
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let globals_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("globals"),
            layout: &g0,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: globals.as_entire_binding() }],
        });
        let shadow_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow map"),
            layout: &g1,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&shadow_view) },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&sampler) },
            ],
        });
        let main_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("main"),
            bind_group_layouts: &[Some(&g0), Some(&g1)],
            immediate_size: 0,
        });
        let shadow_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow"),
            bind_group_layouts: &[Some(&g0)],
            immediate_size: 0,
        });
        let multisample = wgpu::MultisampleState { count: settings.msaa, ..Default::default() };
        let depth = |write: bool, compare| {
            Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(write),
                depth_compare: Some(compare),
                stencil: Default::default(),
                bias: Default::default(),
            })
        };
        let target =
            [Some(wgpu::ColorTargetState { format: COLOR_FORMAT, blend: None, write_mask: wgpu::ColorWrites::ALL })];
        let layouts = vertex_layouts();
        let pipeline = |label, vs, fs, buffers: &[Option<wgpu::VertexBufferLayout<'_>>], cull, depth_state| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&main_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers,
                },
                primitive: wgpu::PrimitiveState { cull_mode: cull, ..Default::default() },
                depth_stencil: depth_state,
                multisample,
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &target,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let sky = pipeline("sky", "vs_sky", "fs_sky", &[], None, depth(false, wgpu::CompareFunction::Always));
        let ground = pipeline("ground", "vs_ground", "fs_ground", &[], None, depth(true, wgpu::CompareFunction::Less));
        let bark = pipeline(
            "bark",
            "vs_tree",
            "fs_bark",
            &layouts,
            Some(wgpu::Face::Back),
            depth(true, wgpu::CompareFunction::Less),
        );
        let leaf = pipeline("leaf", "vs_tree", "fs_leaf", &layouts, None, depth(true, wgpu::CompareFunction::Less));
        let shadow_pipeline = |label, vs, fs: Option<&str>| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&shadow_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers: &layouts,
                },
                primitive: Default::default(),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: wgpu::DepthBiasState { constant: 2, slope_scale: 2.0, clamp: 0.0 },
                }),
                multisample: Default::default(),
                fragment: fs.map(|fs| wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &[],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let shadow = shadow_pipeline("shadow", "vs_shadow", None);
        let shadow_leaf = shadow_pipeline("leaf shadow", "vs_shadow_leaf", Some("fs_shadow_leaf"));
        let size = wgpu::Extent3d { width: settings.width, height: settings.height, depth_or_array_layers: 1 };
        let texture = |label, format, sample_count, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let resolve = texture(
            "image",
            COLOR_FORMAT,
            1,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let color = if settings.msaa > 1 {
            texture("msaa colour", COLOR_FORMAT, settings.msaa, wgpu::TextureUsages::RENDER_ATTACHMENT)
                .create_view(&Default::default())
        } else {
            resolve.create_view(&Default::default())
        };
        let depth_view = texture("depth", DEPTH_FORMAT, settings.msaa, wgpu::TextureUsages::RENDER_ATTACHMENT)
            .create_view(&Default::default());
        let padded_row =
            (settings.width * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("image readback"),
            size: padded_row as u64 * settings.height as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Self {
            settings,
            globals,
            globals_bind,
            shadow_bind,
            sky,
            ground,
            bark,
            leaf,
            shadow,
            shadow_leaf,
            color,
            resolve,
            depth: depth_view,
            shadow_view,
            readback,
            padded_row,
        })
    }

    /// The rendered image (RGBA8 sRGB), for a window to show as a texture.
    pub fn image_view(&self) -> wgpu::TextureView {
        self.resolve.create_view(&Default::default())
    }

    /// The settings in use (MSAA as granted).
    pub fn settings(&self) -> RenderSettings {
        self.settings
    }

    /// Uploads instances.
    pub fn instances(ctx: &GpuContext, instances: &[Instance]) -> wgpu::Buffer {
        let raw: Vec<RawInstance> = instances
            .iter()
            .map(|i| RawInstance {
                model: i.transform.to_cols_array_2d(),
                tint: i.tint.extend(i.leaf_shape.index() as f32).to_array(),
            })
            .collect();
        let raw = if raw.is_empty() { vec![RawInstance::zeroed()] } else { raw };
        ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("instances"),
            contents: bytemuck::cast_slice(&raw),
            usage: wgpu::BufferUsages::VERTEX,
        })
    }

    /// Per-frame constants: the camera, the lighting, and a sun camera fitted to the
    /// bounding sphere of `bounds` (the scene's trees).
    pub fn globals(&self, camera: &Camera, light: &Lighting, bounds: (Vec3, Vec3)) -> RawGlobals {
        let aspect = self.settings.width as f32 / self.settings.height as f32;
        let view_proj = camera.view_proj(aspect);
        let centre = 0.5 * (bounds.0 + bounds.1);
        let radius = (0.5 * (bounds.1 - bounds.0).length()).max(1.0);
        let sun = light.sun_direction.normalize_or(Vec3::Y);
        let up = if sun.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
        let sun_view = Mat4::look_at_rh(centre + sun * 2.0 * radius, centre, up);
        let sun_proj = Mat4::orthographic_rh(-radius, radius, -radius, radius, 0.0, 4.0 * radius);
        RawGlobals {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            sun_view_proj: (sun_proj * sun_view).to_cols_array_2d(),
            eye: camera.eye.extend(1.0).to_array(),
            sun_dir: sun.extend(light.sun_intensity).to_array(),
            sun_colour: light.sun_colour.extend(1.0).to_array(),
            sky_zenith: light.sky_zenith.extend(1.0).to_array(),
            sky_horizon: light.sky_horizon.extend(1.0).to_array(),
            ground: light.ground.extend(light.ground_half_size).to_array(),
            params: [1.0 / self.settings.shadow_size as f32, light.fog_distance.max(1.0), 0.0, 0.0],
        }
    }

    fn draw_trees(
        pass: &mut wgpu::RenderPass<'_>,
        items: &[DrawItem<'_>],
        bark: Option<&wgpu::RenderPipeline>,
        leaf: Option<&wgpu::RenderPipeline>,
    ) {
        for (pipeline, is_leaf) in [(bark, false), (leaf, true)] {
            if let Some(p) = pipeline {
                pass.set_pipeline(p);
            }
            for item in items {
                let m = if is_leaf { &item.leaves } else { &item.bark };
                if m.index_count == 0 || item.instance_count == 0 {
                    continue;
                }
                pass.set_vertex_buffer(1, m.uv.slice(..));
                pass.set_vertex_buffer(2, item.instances.slice(..));
                pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
                let first = item.first_instance;
                if m.per_instance_vertices == 0 {
                    pass.set_vertex_buffer(0, m.vertices.slice(..));
                    pass.draw_indexed(0..m.index_count, 0, first..first + item.instance_count);
                } else {
                    // Instance k's vertices from k × n on, its texture coordinates the
                    // shared ones: the vertex stream bound from there.
                    let stride = std::mem::size_of::<sylva_core::mesh::RawVertex>() as u64;
                    let n = m.per_instance_vertices as u64;
                    for k in 0..item.instance_count {
                        pass.set_vertex_buffer(0, m.vertices.slice(k as u64 * n * stride..(k as u64 + 1) * n * stride));
                        pass.draw_indexed(0..m.index_count, 0, first + k..first + k + 1);
                    }
                }
            }
        }
    }

    /// Records a frame (shadow pass and main pass) into `encoder`; the image lands in the
    /// resolve texture. `globals` from [`Self::globals`].
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        globals: &RawGlobals,
        items: &[DrawItem<'_>],
    ) {
        ctx.queue.write_buffer(&self.globals, 0, bytemuck::bytes_of(globals));
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.shadow_view,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &self.globals_bind, &[]);
            Self::draw_trees(&mut pass, items, Some(&self.shadow), Some(&self.shadow_leaf));
        }
        let msaa = self.settings.msaa > 1;
        let resolve_view = self.resolve.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("main"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.color,
                depth_slice: None,
                resolve_target: msaa.then_some(&resolve_view),
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: if msaa { wgpu::StoreOp::Discard } else { wgpu::StoreOp::Store },
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Discard }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &self.globals_bind, &[]);
        pass.set_bind_group(1, &self.shadow_bind, &[]);
        pass.set_pipeline(&self.sky);
        pass.draw(0..3, 0..1);
        pass.set_pipeline(&self.ground);
        pass.draw(0..6, 0..1);
        Self::draw_trees(&mut pass, items, Some(&self.bark), Some(&self.leaf));
    }

    /// Renders a frame and reads it back as tightly packed RGBA8 (sRGB), row by row from the
    /// top.
    pub fn render(&self, ctx: &GpuContext, globals: &RawGlobals, items: &[DrawItem<'_>]) -> Result<Vec<u8>, GpuError> {
        let mut encoder = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        self.record(ctx, &mut encoder, globals, items);
        self.read_image(ctx, encoder)
    }

    /// Finishes `encoder` with a copy of the image and reads it back.
    pub fn read_image(&self, ctx: &GpuContext, mut encoder: wgpu::CommandEncoder) -> Result<Vec<u8>, GpuError> {
        let (w, h) = (self.settings.width, self.settings.height);
        encoder.copy_texture_to_buffer(
            self.resolve.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
        ctx.submit([encoder.finish()]);
        crate::kernel::map_read(ctx, &self.readback, |bytes| {
            let mut out = Vec::with_capacity((w * h * 4) as usize);
            for row in bytes.chunks(self.padded_row as usize).take(h as usize) {
                out.extend_from_slice(&row[..(w * 4) as usize]);
            }
            out
        })
    }
}
