//! Hot reload and save: the scene file and the files it names are polled for changes; a
//! changed scene that parses replaces the running one, one that does not leaves it running
//! and shows the error. Saving writes the scene (and the wind edited in the panel, beside
//! it) completely or not at all.

use crate::session::Session;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};
use sylva_core::scene::Scene;
use sylva_core::wind::{Constant, WindField, WindScene};

/// How often the scene's files are checked for changes, s.
const WATCH_INTERVAL_S: f64 = 0.5;

/// The files whose changes reload the scene, with their last modification times.
#[derive(Debug)]
pub(crate) struct Watch {
    files: Vec<(PathBuf, Option<SystemTime>)>,
    last: Instant,
}

fn mtime(p: &Path) -> Option<SystemTime> {
    std::fs::metadata(p).and_then(|m| m.modified()).ok()
}

impl Watch {
    /// The scene file itself, its wind file and its species or grammar files (presets by
    /// name are not files).
    pub(crate) fn of(scene: &Scene, path: Option<&Path>) -> Self {
        let mut files: Vec<PathBuf> = path.iter().map(|p| p.to_path_buf()).collect();
        let named = std::iter::once(&scene.wind).chain(scene.trees.iter().map(|t| &t.species));
        for name in named {
            let p = PathBuf::from(scene.resolve_path(name));
            if p.is_file() {
                files.push(p);
            }
        }
        Self { files: files.into_iter().map(|p| (p.clone(), mtime(&p))).collect(), last: Instant::now() }
    }

    /// Whether a file changed since the last look (at most every [`WATCH_INTERVAL_S`]).
    fn changed(&mut self, force: bool) -> bool {
        if !force && self.last.elapsed().as_secs_f64() < WATCH_INTERVAL_S {
            return false;
        }
        self.last = Instant::now();
        let changed = self.files.iter().any(|(p, m)| mtime(p) != *m);
        for (p, m) in &mut self.files {
            *m = mtime(p);
        }
        changed || force
    }
}

impl Session {
    /// Checks the watched files and reloads the scene when one changed (or when forced).
    pub(crate) fn poll_reload(&mut self, force: bool) {
        if !self.watch.changed(force) {
            return;
        }
        let Some(path) = self.path.clone() else { return };
        let result = Scene::load(&path).map_err(anyhow::Error::from).and_then(|scene| {
            self.world.set_scene(scene)?;
            Ok(())
        });
        match result {
            Ok(()) => {
                self.reload_error = None;
                self.wind_edited = false;
                self.forest = vec![0; self.world.scene().trees.len()];
                self.watch = Watch::of(self.world.scene(), Some(&path));
            }
            Err(e) => self.reload_error = Some(format!("{e:#}")),
        }
    }

    /// Saves the scene (to its file, or `scene.toml`); wind edited in the panel and the
    /// extra constant wind go to a wind file beside it, which the scene then names.
    pub(crate) fn save(&mut self) -> Result<PathBuf> {
        let path = self.path.clone().unwrap_or_else(|| PathBuf::from("scene.toml"));
        let mut scene = self.world.scene().clone();
        let w = self.world.wind();
        if self.wind_edited || w.extra.is_some() || !w.base_on {
            let mut wind = if w.base_on { w.base.clone() } else { WindScene::default() };
            if let Some((deg, speed)) = w.extra {
                let a = deg.to_radians();
                wind.fields.push(WindField::Constant(Constant { direction: [a.cos(), 0.0, a.sin()], speed }));
            }
            let stem = path.file_stem().map_or("scene".into(), |s| s.to_string_lossy().into_owned());
            let name = format!("{stem}.wind.toml");
            wind.save(&path.with_file_name(&name))?;
            scene.wind = name;
            self.world.edit_wind(|w| {
                w.base = wind;
                w.extra = None;
                w.base_on = true;
                true
            })?;
            self.wind_edited = false;
        }
        let text = scene.to_toml();
        sylva_core::io::write_atomic(&path, |f| f.write_all(text.as_bytes()))
            .with_context(|| format!("writing {}", path.display()))?;
        if self.path.is_none() {
            self.path = Some(path.clone());
        }
        // Our own write is not an edit to reload.
        self.watch = Watch::of(&scene, Some(&path));
        Ok(path)
    }
}
