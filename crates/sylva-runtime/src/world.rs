//! The world: a scene's trees as they run, the wind they feel, the clock, and what the
//! renderer draws.

use crate::RuntimeError;
use crate::registry::MethodRegistry;
use crate::tree::WorldTree;
use crate::wind::{Effect, WorldWind};
use glam::Vec3;
use std::sync::Arc;
use sylva_core::scene::{Scene, SceneTree};
use sylva_core::wind::WindScene;
use sylva_gpu::GpuContext;
use sylva_gpu::render::DrawItem;

/// A scene's trees, grown, animated and meshed on one device (see the crate docs).
#[derive(Debug)]
pub struct World {
    ctx: Arc<GpuContext>,
    registry: Arc<MethodRegistry>,
    scene: Scene,
    trees: Vec<WorldTree>,
    wind: WorldWind,
    time: f32,
    dt: f32,
    carry: f32,
}

impl World {
    /// The scene's trees with the built-in methods, stepped at the scene's `sim_rate`.
    pub fn new(ctx: Arc<GpuContext>, scene: Scene) -> Result<Self, RuntimeError> {
        let dt = 1.0 / scene.output.sim_rate;
        Self::with(ctx, scene, Arc::new(MethodRegistry::builtin()), dt)
    }

    /// The scene's trees with the methods of `registry`, stepped by `dt` seconds.
    pub fn with(
        ctx: Arc<GpuContext>,
        scene: Scene,
        registry: Arc<MethodRegistry>,
        dt: f32,
    ) -> Result<Self, RuntimeError> {
        if !(dt.is_finite() && dt > 0.0 && dt <= 1.0) {
            return Err(RuntimeError::Limit(format!("simulation step {dt} s: expected more than 0 and at most 1 s")));
        }
        scene.check_methods(&registry.names())?;
        let base = WindScene::resolve(&scene.resolve_path(&scene.wind))
            .map_err(|source| RuntimeError::SceneWind { file: scene.file.clone(), source: Box::new(source) })?;
        let wind = WorldWind::new(&ctx, base)?;
        let mut world = Self { ctx, registry, scene, trees: Vec::new(), wind, time: 0.0, dt, carry: 0.0 };
        world.trees = world.build_all()?;
        Ok(world)
    }

    fn build_all(&mut self) -> Result<Vec<WorldTree>, RuntimeError> {
        // Every tree is grown and the scene's size checked before anything is set up.
        let mut grown = Vec::with_capacity(self.scene.trees.len());
        let mut total = 0usize;
        for (i, st) in self.scene.trees.iter().enumerate() {
            let tree = WorldTree::grow(&self.scene, i, st, total)?;
            total += WorldTree::elements(&tree, 1 + st.copies.len());
            grown.push(tree);
        }
        let mut built = Vec::with_capacity(grown.len());
        for (i, tree) in grown.into_iter().enumerate() {
            let st = self.scene.trees[i].clone();
            let (ctx, registry, scene) = (&self.ctx, &self.registry, &self.scene);
            built.push(WorldTree::build(ctx, registry, scene, i, &st, &mut self.wind, self.dt, Some(tree), 0)?);
        }
        Ok(built)
    }

    /// The device.
    pub fn ctx(&self) -> &Arc<GpuContext> {
        &self.ctx
    }

    /// The methods this world builds.
    pub fn registry(&self) -> &MethodRegistry {
        &self.registry
    }

    /// The scene as it runs (edits included).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The trees, in the scene's order.
    pub fn trees(&self) -> &[WorldTree] {
        &self.trees
    }

    /// Tree `i`.
    pub fn tree(&self, i: usize) -> Result<&WorldTree, RuntimeError> {
        self.trees.get(i).ok_or(RuntimeError::NoTree { index: i, trees: self.trees.len() })
    }

    /// The scene's clock, s.
    pub fn time(&self) -> f32 {
        self.time
    }

    /// The simulation step, s.
    pub fn dt(&self) -> f32 {
        self.dt
    }

    /// Lets the wind move every simulation `steps` steps before the first frame: stateful
    /// methods start at rest. Phase groups pre-roll further, each by its own lead.
    pub fn preroll(&mut self, steps: usize) {
        self.time += steps as f32 * self.dt;
        for t in &mut self.trees {
            t.advance(&self.ctx, self.dt, steps, true);
        }
    }

    /// Advances every simulation `steps` steps (GPU work submitted, not waited for); live
    /// effects that are over are dropped.
    pub fn step(&mut self, steps: usize) -> Result<(), RuntimeError> {
        // What is over when these steps start: a blend still has its tail to run.
        if self.wind.expire(self.time) {
            self.wind_changed()?;
        }
        self.time += steps as f32 * self.dt;
        for t in &mut self.trees {
            t.advance(&self.ctx, self.dt, steps, false);
        }
        Ok(())
    }

    /// Advances by `seconds` of simulated time in whole steps, carrying the remainder to the
    /// next call, at most `max_steps` (a slow frame slows the clock rather than spiral);
    /// returns the steps taken.
    pub fn advance(&mut self, seconds: f32, max_steps: usize) -> Result<usize, RuntimeError> {
        self.carry += seconds.max(0.0);
        let steps = ((self.carry / self.dt).floor() as usize).min(max_steps);
        self.carry = (self.carry - steps as f32 * self.dt).clamp(0.0, self.dt);
        self.step(steps)?;
        Ok(steps)
    }

    /// Records every tree's mesh of its current pose into `encoder`.
    pub fn record(&mut self, encoder: &mut wgpu::CommandEncoder) {
        for t in &mut self.trees {
            t.record(&self.ctx, encoder);
        }
    }

    /// What the renderer draws: every tree's meshes at their instances.
    pub fn draw_items(&self) -> Vec<DrawItem<'_>> {
        self.trees.iter().flat_map(WorldTree::draw_items).collect()
    }

    /// Scene-space bounds of every instance of every tree.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.trees.iter().fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), t| {
            (lo.min(t.bounds.0), hi.max(t.bounds.1))
        })
    }

    /// Triangles drawn per frame.
    pub fn triangles(&self) -> usize {
        self.trees.iter().map(|t| t.triangles).sum()
    }

    /// Instances drawn.
    pub fn instances(&self) -> usize {
        self.trees.iter().map(|t| t.instances).sum()
    }

    /// The wind.
    pub fn wind(&self) -> &WorldWind {
        &self.wind
    }

    /// Edits the wind (`edit` returns whether it changed anything); a change is composed,
    /// uploaded once and handed to every simulation.
    pub fn edit_wind(&mut self, edit: impl FnOnce(&mut WorldWind) -> bool) -> Result<(), RuntimeError> {
        if edit(&mut self.wind) {
            self.wind_changed()?;
        }
        Ok(())
    }

    /// Places a live effect at the current time.
    pub fn place(&mut self, effect: Effect) -> Result<(), RuntimeError> {
        if let Some(f) = effect.field(self.time) {
            self.wind.push_effect(f);
            self.wind_changed()?;
        }
        Ok(())
    }

    /// Removes every live effect.
    pub fn clear_effects(&mut self) -> Result<(), RuntimeError> {
        self.wind.clear_effects();
        self.wind_changed()
    }

    fn wind_changed(&mut self) -> Result<(), RuntimeError> {
        self.wind.recompose(&self.ctx, Some(self.time))?;
        for t in &mut self.trees {
            t.set_wind(&self.ctx, &mut self.wind)?;
        }
        Ok(())
    }

    /// Replaces tree `i` by `st`, at rest at the current time (its phase groups pre-rolled
    /// by their leads). On an error the running tree is left as it was.
    pub fn rebuild_tree(&mut self, i: usize, st: SceneTree) -> Result<(), RuntimeError> {
        if i >= self.trees.len() {
            return Err(RuntimeError::NoTree { index: i, trees: self.trees.len() });
        }
        let mut scene = self.scene.clone();
        scene.trees[i] = st;
        scene.check().map_err(|(field, value, expected)| {
            RuntimeError::Limit(format!("{field} = {value}: expected {expected}"))
        })?;
        scene.check_methods(&self.registry.names())?;
        let st = scene.trees[i].clone();
        let others = self.trees.iter().enumerate().filter(|(k, _)| *k != i).map(|(_, t)| t.scene_elements()).sum();
        let mut tree =
            WorldTree::build(&self.ctx, &self.registry, &scene, i, &st, &mut self.wind, self.dt, None, others)?;
        tree.start_at(&self.ctx, self.dt, self.time);
        self.trees[i] = tree;
        self.scene = scene;
        Ok(())
    }

    /// Replaces the whole scene (a reload): every tree rebuilt at rest at the current time,
    /// the wind the new scene's plus the live effects. On an error the running world is
    /// left as it was.
    pub fn set_scene(&mut self, scene: Scene) -> Result<(), RuntimeError> {
        scene.check_methods(&self.registry.names())?;
        let base = WindScene::resolve(&scene.resolve_path(&scene.wind))
            .map_err(|source| RuntimeError::SceneWind { file: scene.file.clone(), source: Box::new(source) })?;
        let old_scene = std::mem::replace(&mut self.scene, scene);
        let old_base = std::mem::replace(&mut self.wind.base, base);
        let rebuilt = self.wind.recompose(&self.ctx, None).map_err(RuntimeError::from).and_then(|()| self.build_all());
        match rebuilt {
            Ok(mut trees) => {
                for t in &mut trees {
                    t.start_at(&self.ctx, self.dt, self.time);
                }
                self.trees = trees;
                Ok(())
            }
            Err(e) => {
                self.scene = old_scene;
                self.wind.base = old_base;
                self.wind.recompose(&self.ctx, None)?;
                Err(e)
            }
        }
    }

    /// Debug overlay: tree `i`'s skeleton (its first instance) as segments in scene space.
    pub fn skeleton(&self, i: usize) -> Result<Vec<[Vec3; 2]>, RuntimeError> {
        let t = self.tree(i)?;
        let pose = t.pose(&self.ctx)?;
        Ok((0..t.tree.segments.len())
            .map(|s| [t.transform.transform_point3(pose.start[s]), t.transform.transform_point3(pose.end(&t.tree, s))])
            .collect())
    }

    /// Debug overlay: the centres of tree `i`'s clusters (its first simulation) in scene
    /// space, for methods that have clusters.
    pub fn cluster_centres(&self, i: usize) -> Result<Option<Vec<Vec3>>, RuntimeError> {
        let t = self.tree(i)?;
        Ok(t.simulations()[0]
            .cluster_centres(&self.ctx)?
            .map(|c| c.into_iter().map(|p| t.transform.transform_point3(p)).collect()))
    }

    /// Debug overlay: the wind on an `n × n` grid over the scene's bounds, 1.5 m above the
    /// ground: (point, velocity).
    pub fn wind_arrows(&self, n: usize) -> Vec<(Vec3, Vec3)> {
        let (lo, hi) = self.bounds();
        if !(lo.is_finite() && hi.is_finite()) {
            return Vec::new();
        }
        let packed = self.wind.packed();
        let mut out = Vec::with_capacity(n * n);
        for i in 0..n {
            for k in 0..n {
                let p = Vec3::new(
                    lo.x + (hi.x - lo.x) * (i as f32 + 0.5) / n as f32,
                    1.5,
                    lo.z + (hi.z - lo.z) * (k as f32 + 0.5) / n as f32,
                );
                out.push((p, packed.at(p, self.time)));
            }
        }
        out
    }
}
