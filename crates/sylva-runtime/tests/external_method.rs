//! A fifth method, defined here and not in Sylva's crates, registered with the runtime and
//! run from a scene file on the CPU and the GPU: the seam is all a method needs.
//!
//! The method is a stiff rigid-body sway: the whole tree turns about its root joint as one
//! damped oscillator (natural frequency `f`, damping ratio `ζ`) driven by the wind at its
//! crown, the static lean `gain · |u| u`. Its state is the lean as a horizontal vector
//! `b = (bx, bz)` (rad, the crown's direction of travel) and its rate; the root segment
//! turns by the rotation vector `(bz, 0, −bx)`, every other segment rides along.

mod common;

use glam::{Quat, Vec3};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::methods::{Animator, Method, MethodError, MethodOptions, Simulation};
use sylva_core::pose::SeamPose;
use sylva_core::scene::Scene;
use sylva_core::wind::PackedWind;
use sylva_gpu::kernel::{Kernel, upload};
use sylva_gpu::methods::{BuildError, GpuAnimator};
use sylva_gpu::pose::GpuPose;
use sylva_gpu::shaders::{NOISE, QUAT, WIND};
use sylva_gpu::wind::GpuWind;
use sylva_gpu::{GpuContext, GpuError};
use sylva_runtime::{MethodEntry, MethodRegistry, RuntimeError, World};

/// Parameters: natural frequency (Hz), damping ratio, static lean per (m/s)² (rad).
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
struct RigidParams {
    frequency: f32,
    damping_ratio: f32,
    gain: f32,
}

impl Default for RigidParams {
    fn default() -> Self {
        Self { frequency: 0.6, damping_ratio: 0.1, gain: 0.002 }
    }
}

#[derive(Debug, Clone)]
struct Rigid {
    params: RigidParams,
    /// Where the wind is sampled: the crown's centre.
    crown: Vec3,
}

#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct RigidState {
    /// (bx, bz, rate x, rate z).
    lean: [f32; 4],
    time: f32,
}

impl Rigid {
    fn new(tree: &Tree, params: RigidParams) -> Self {
        let (lo, hi) = tree.bounds();
        Self { params, crown: Vec3::new(0.0, 0.5 * (lo.y + hi.y) + 0.25 * (hi.y - lo.y), 0.0) }
    }

    /// One semi-implicit Euler step (the WGSL below does the same operations in order).
    fn integrate(&self, s: [f32; 4], u: Vec3, dt: f32) -> [f32; 4] {
        let w0 = std::f32::consts::TAU * self.params.frequency;
        let k = w0 * w0;
        let c = 2.0 * self.params.damping_ratio * w0;
        let speed = (u.x * u.x + u.z * u.z).sqrt();
        let fx = k * self.params.gain * speed * u.x;
        let fz = k * self.params.gain * speed * u.z;
        let vx = s[2] + (fx - k * s[0] - c * s[2]) * dt;
        let vz = s[3] + (fz - k * s[1] - c * s[3]) * dt;
        [s[0] + vx * dt, s[1] + vz * dt, vx, vz]
    }
}

fn root_rotation(lean: [f32; 4]) -> Quat {
    let r = Vec3::new(lean[1], 0.0, -lean[0]);
    let a = r.length();
    if a == 0.0 { Quat::IDENTITY } else { Quat::from_axis_angle(r / a, a) }
}

impl Method for Rigid {
    type State = RigidState;
    fn name(&self) -> &'static str {
        "rigid"
    }
    fn rest_state(&self, _tree: &Tree) -> RigidState {
        RigidState::default()
    }
    fn step(&self, _tree: &Tree, wind: &PackedWind, state: &mut RigidState, dt: f32) {
        let t = state.time + dt;
        state.lean = self.integrate(state.lean, wind.at(self.crown, t), dt);
        state.time = t;
    }
    fn time(&self, state: &RigidState) -> f32 {
        state.time
    }
    fn set_time(&self, state: &mut RigidState, time: f32) {
        state.time = time;
    }
    fn seam(&self, tree: &Tree, _wind: &PackedWind, state: &RigidState, out: &mut SeamPose) {
        let q = root_rotation(state.lean).to_array();
        let delta: Vec<[f32; 4]> = (0..tree.segments.len())
            .map(|i| if tree.segments.parent[i] == sylva_core::NONE { q } else { [0.0, 0.0, 0.0, 1.0] })
            .collect();
        *out = SeamPose::from_rotations(tree, &delta);
    }
}

fn parse(options: &MethodOptions) -> Result<RigidParams, MethodError> {
    let p: RigidParams = options.parse("rigid")?;
    if !(p.frequency > 0.0 && p.frequency.is_finite()) {
        return Err(MethodError::Param {
            method: "rigid",
            field: "frequency".into(),
            value: p.frequency.to_string(),
            expected: "a positive frequency (Hz)".into(),
        });
    }
    Ok(p)
}

fn rigid_cpu(tree: Arc<Tree>, options: &MethodOptions) -> Result<Box<dyn Animator>, MethodError> {
    let m = Rigid::new(&tree, parse(options)?);
    Ok(Simulation::boxed(tree, m))
}

/// Step: one invocation integrates the lean (bindings 2 state, 3 step values).
const RIGID_STEP: &str = r#"
struct RigidStep { crown: vec4<f32>, k: f32, c: f32, gain: f32, dt: f32, time: f32, _a: f32, _b: f32, _c: f32 }
@group(0) @binding(2) var<storage, read_write> state: vec4<f32>;
@group(0) @binding(3) var<storage, read> step: RigidStep;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x != 0u) { return; }
    let u = wind_at(step.crown.xyz, step.time);
    let s = state;
    let speed = sqrt(u.x * u.x + u.z * u.z);
    let fx = step.k * step.gain * speed * u.x;
    let fz = step.k * step.gain * speed * u.z;
    let vx = s.z + (fx - step.k * s.x - step.c * s.z) * step.dt;
    let vz = s.w + (fz - step.k * s.y - step.c * s.w) * step.dt;
    state = vec4<f32>(s.x + vx * step.dt, s.y + vz * step.dt, vx, vz);
}
"#;

/// Rotations: the root turns by the lean, the rest ride along (bindings 0 parents,
/// 1 state, 2 delta).
const RIGID_DELTA: &str = r#"
const NONE: u32 = 0xffffffffu;
@group(0) @binding(0) var<storage, read> parents: array<u32>;
@group(0) @binding(1) var<storage, read> state: vec4<f32>;
@group(0) @binding(2) var<storage, read_write> delta: array<vec4<f32>>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= arrayLength(&parents)) { return; }
    var q = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    if (parents[i] == NONE) {
        q = quat_from_rotation_vector(vec3<f32>(state.y, 0.0, -state.x));
    }
    delta[i] = q;
}
"#;

#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct RawRigidStep {
    crown: [f32; 4],
    k: f32,
    c: f32,
    gain: f32,
    dt: f32,
    time: f32,
    _pad: [f32; 3],
}

#[derive(Debug)]
struct GpuRigid {
    tree: Arc<Tree>,
    method: Rigid,
    step_kernel: Arc<Kernel>,
    delta_kernel: Arc<Kernel>,
    pose: GpuPose,
    wind: GpuWind,
    state: wgpu::Buffer,
    step: wgpu::Buffer,
    time: f32,
}

impl GpuRigid {
    fn new(ctx: &GpuContext, tree: Arc<Tree>, method: Rigid, wind: &GpuWind) -> Result<Self, GpuError> {
        Ok(Self {
            step_kernel: Kernel::cached(ctx, "rigid_step", &[NOISE, WIND, RIGID_STEP]),
            delta_kernel: Kernel::cached(ctx, "rigid_delta", &[QUAT, RIGID_DELTA]),
            pose: GpuPose::new(ctx, &tree)?,
            wind: wind.clone(),
            state: upload(ctx, "rigid state", &[[0.0f32; 4]])?,
            step: upload(ctx, "rigid step", &[bytemuck::Zeroable::zeroed(); 1] as &[RawRigidStep])?,
            tree,
            method,
            time: 0.0,
        })
    }
}

impl GpuAnimator for GpuRigid {
    fn name(&self) -> &'static str {
        "rigid"
    }
    fn tree(&self) -> &Arc<Tree> {
        &self.tree
    }
    fn set_wind(&mut self, wind: &GpuWind) {
        self.wind = wind.clone();
    }
    fn reset(&mut self, ctx: &GpuContext, time: f32) {
        ctx.queue.write_buffer(&self.state, 0, bytemuck::cast_slice(&[[0.0f32; 4]]));
        self.pose.write_rest(ctx, &self.tree);
        self.time = time;
    }
    fn advance(&mut self, ctx: &GpuContext, dt: f32, steps: usize) {
        let w0 = std::f32::consts::TAU * self.method.params.frequency;
        let n = self.tree.segments.len() as u32;
        for _ in 0..steps.max(1) {
            let live = steps > 0;
            if live {
                self.time += dt;
                let step = RawRigidStep {
                    crown: self.method.crown.extend(0.0).to_array(),
                    k: w0 * w0,
                    c: 2.0 * self.method.params.damping_ratio * w0,
                    gain: self.method.params.gain,
                    dt,
                    time: self.time,
                    _pad: [0.0; 3],
                };
                ctx.queue.write_buffer(&self.step, 0, bytemuck::bytes_of(&step));
            }
            let mut e = ctx.device.create_command_encoder(&Default::default());
            if live {
                self.step_kernel.record(
                    ctx,
                    &mut e,
                    &[&self.wind.fields, &self.wind.waves, &self.state, &self.step],
                    1,
                );
            }
            self.delta_kernel.record(
                ctx,
                &mut e,
                &[self.pose.parents_buffer(), &self.state, self.pose.delta_buffer()],
                n,
            );
            self.pose.record(ctx, &mut e);
            ctx.submit([e.finish()]);
        }
    }
    fn time(&self) -> f32 {
        self.time
    }
    fn pose_buffers(&self) -> &GpuPose {
        &self.pose
    }
}

fn rigid_gpu(
    ctx: &GpuContext,
    tree: Arc<Tree>,
    options: &MethodOptions,
    wind: &GpuWind,
    _instances: &[sylva_core::pose::Placement],
) -> Result<Box<dyn GpuAnimator>, BuildError> {
    let m = Rigid::new(&tree, parse(options)?);
    Ok(Box::new(GpuRigid::new(ctx, tree, m, wind)?))
}

const RIGID: MethodEntry = MethodEntry {
    name: "rigid",
    summary: "a stiff rigid-body sway about the root (a test of the seam)",
    per_instance: false,
    cpu: rigid_cpu,
    gpu: Some(rigid_gpu),
};

fn scene(backend: &str, params: &str) -> Scene {
    let text = format!(
        "wind = \"gusty\"\n[output]\nsim_rate = 60\n[[tree]]\nspecies = \"palm\"\nmethod = \"rigid\"\nbackend = \"{backend}\"\n{params}copies = [{{ position = [6.0, 0.0, -4.0] }}]\n"
    );
    Scene::from_toml(&text, "rigid.toml", std::path::Path::new(".")).unwrap()
}

fn registry() -> Arc<MethodRegistry> {
    let mut r = MethodRegistry::builtin();
    r.register(RIGID).unwrap();
    Arc::new(r)
}

#[test]
fn a_method_defined_outside_sylva_runs_through_the_runtime_on_cpu_and_gpu() {
    let Some(ctx) = common::gpu() else { return };
    let mut poses = Vec::new();
    for backend in ["cpu", "gpu"] {
        let mut world = World::with(ctx.clone(), scene(backend, ""), registry(), 1.0 / 60.0).unwrap();
        assert_eq!(world.trees()[0].method, "rigid");
        assert_eq!(world.trees()[0].on_gpu, backend == "gpu");
        world.preroll(120);
        world.step(60).unwrap();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        world.record(&mut encoder);
        ctx.submit([encoder.finish()]);
        assert_eq!(world.draw_items().len(), 2, "{backend}: two phase groups, a mesh each");
        let pose = world.trees()[0].pose(&ctx).unwrap();
        let t = &world.trees()[0].tree;
        pose.check_sound(t).unwrap();
        let moved = (pose.end(t, t.segments.len() - 1) - t.segments.end(t.segments.len() - 1)).length();
        assert!(moved > 0.01, "{backend}: the gusty wind moved the crown by only {moved} m");
        poses.push(pose);
    }
    // The two backends run the same oscillator: crowns agree within 1e-4 × height.
    let t =
        sylva_core::species::SpeciesSource::resolve("palm").unwrap().generate(1, &Default::default(), None).unwrap();
    let tol = 1e-4 * t.height();
    for i in 0..t.segments.len() {
        let d = (poses[0].start[i] - poses[1].start[i]).length();
        assert!(d <= tol, "segment {i}: CPU and GPU joints {d} m apart (tolerance {tol} m)");
    }
}

#[test]
fn a_registered_method_reads_its_parameters_and_refuses_bad_ones_by_line() {
    let Some(ctx) = common::gpu() else { return };
    // A more compliant tree (a larger static lean per (m/s)²) leans further in the same wind.
    let lean = |params: &str| {
        let mut world = World::with(ctx.clone(), scene("cpu", params), registry(), 1.0 / 60.0).unwrap();
        world.preroll(300);
        let t = &world.trees()[0].tree;
        let pose = world.trees()[0].pose(&ctx).unwrap();
        (pose.end(t, t.segments.len() - 1) - t.segments.end(t.segments.len() - 1)).length()
    };
    let (soft, stiff) = (lean("params = { gain = 0.004 }\n"), lean("params = { gain = 0.001 }\n"));
    assert!(stiff < 0.5 * soft, "stiff {stiff} m, soft {soft} m");
    let e =
        World::with(ctx.clone(), scene("cpu", "params = { frequency = -1.0 }\n"), registry(), 1.0 / 60.0).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, RuntimeError::Method { line: 8, .. }), "{msg}");
    assert!(msg.contains("rigid.toml:8") && msg.contains("frequency") && msg.contains("positive"), "{msg}");
    let e = World::with(ctx.clone(), scene("cpu", "params = { stiffness = 1.0 }\n"), registry(), 1.0 / 60.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("stiffness"), "{e}");
    // Without the registration the name is unknown, and the error says which ones exist.
    let e = World::new(ctx.clone(), scene("cpu", "")).unwrap_err().to_string();
    assert!(e.contains("rigid.toml:6") && e.contains("\"rigid\"") && e.contains("zioma, akagi, skjermo, hsm"), "{e}");
    // A name is registered once.
    let mut r = MethodRegistry::builtin();
    r.register(RIGID).unwrap();
    assert!(r.register(RIGID).is_err());
    assert!(r.register(MethodEntry { name: "Not Valid", ..RIGID }).is_err());
    assert_eq!(r.names(), ["zioma", "akagi", "skjermo", "hsm", "rigid"]);
}
