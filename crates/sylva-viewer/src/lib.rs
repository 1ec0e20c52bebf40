//! Sylva's interactive viewer (`sylva view`): a window (winit) shows a scene through the
//! same renderer as `sylva render`, beside an egui panel: camera, time, wind (blasts,
//! vortices and pushes placed by clicking the ground), per-tree species, seed, method,
//! backend and forest size, overlays and counts. It runs the scene through the runtime's
//! [`sylva_runtime::World`].
//!
//! * [`window`]: events, the frame, the 3D view, screenshots and reports;
//! * `panel`, `overlay`, `camera`: the panel, what is drawn over the view, the orbit camera;
//! * `reload`: the scene's files polled and reloaded, saving;
//! * [`script`]: scripted input for tests and demos.

mod camera;
mod overlay;
mod panel;
mod reload;
pub mod script;
mod session;
pub mod window;

pub use script::{Command, Tool, parse_script};
use std::path::PathBuf;

/// What `sylva view` opens.
#[derive(Debug, Clone, Default)]
pub struct ViewOptions {
    /// The scene file; the built-in default scene when absent.
    pub scene: Option<PathBuf>,
    /// Window width, pixels.
    pub width: u32,
    /// Window height, pixels.
    pub height: u32,
}

/// Opens the window and runs until it closes or the script quits.
pub fn run(options: &ViewOptions, script: Vec<Command>) -> anyhow::Result<()> {
    window::run(options, script)
}
