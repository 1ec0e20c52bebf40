//! `sylva view`: the interactive viewer (`sylva-viewer`), behind the cargo feature `viewer`:
//! the arguments, the script file and the display check.

use anyhow::{Result, bail};
use std::path::PathBuf;

/// Arguments of `sylva view`.
#[derive(clap::Args, Debug, Default)]
pub struct ViewArgs {
    /// Scene file (TOML); the built-in default scene when absent. Reloaded when it or a
    /// file it names changes on disk.
    pub scene: Option<PathBuf>,
    /// Window width, pixels.
    #[arg(long, default_value_t = 1280)]
    pub width: u32,
    /// Window height, pixels.
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// Replay the inputs in this file, then keep running unless it ends with `quit`.
    ///
    /// One command per line (`#` starts a comment): `frames N` (run N frames of 1/60 s ×
    /// the time scale), `click U V` (click the view at 0…1 from its top left with the tool),
    /// `tool blast|vortex|push|none`, `blast X Z` (at ground point x, z), `wind DEG SPEED`
    /// (an extra constant wind), `method TREE NAME`, `forest TREE N` (N instances),
    /// `overwrite-scene FILE` (copy FILE over the scene file, as an editor would),
    /// `screenshot OUT.png` (the 3D view), `report OUT.json` (frames, time, mean stage
    /// times, every tree's displacement, reload status), `quit`.
    #[arg(long, verbatim_doc_comment)]
    pub script: Option<PathBuf>,
}

/// Runs `sylva view`.
pub fn run(args: &ViewArgs) -> Result<()> {
    let script = match &args.script {
        Some(p) => {
            let text = sylva_core::io::read_text(p).map_err(|e| anyhow::anyhow!("{}: {e}", p.display()))?;
            parse(&text, &p.display().to_string())?
        }
        None => Vec::new(),
    };
    if !(64..=8192).contains(&args.width) || !(64..=8192).contains(&args.height) {
        bail!("--width/--height {}×{}: expected 64 to 8192 pixels", args.width, args.height);
    }
    let has_display = ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()));
    if !has_display {
        bail!(
            "no display to open a window on (DISPLAY and WAYLAND_DISPLAY are unset). \
             `sylva render` renders the same scene to a GIF, PNG frames and MP4 without one"
        );
    }
    run_window(args, script)
}

#[cfg(feature = "viewer")]
fn parse(text: &str, file: &str) -> Result<Vec<sylva_viewer::Command>> {
    sylva_viewer::parse_script(text, file)
}

#[cfg(feature = "viewer")]
fn run_window(args: &ViewArgs, script: Vec<sylva_viewer::Command>) -> Result<()> {
    let options = sylva_viewer::ViewOptions { scene: args.scene.clone(), width: args.width, height: args.height };
    sylva_viewer::run(&options, script)
}

#[cfg(not(feature = "viewer"))]
fn parse(_: &str, _: &str) -> Result<Vec<()>> {
    Ok(Vec::new())
}

#[cfg(not(feature = "viewer"))]
fn run_window(_: &ViewArgs, _: Vec<()>) -> Result<()> {
    bail!(
        "this sylva was built without the viewer (cargo feature `viewer`); rebuild with default features, or use `sylva render`"
    )
}
