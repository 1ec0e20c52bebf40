//! An application embeds Sylva: it creates its own wgpu device, hands it to the runtime,
//! steps a scene and writes a few frames to PNG.
//!
//! `cargo run -p sylva-runtime --example headless -- [OUT_DIR]` (default `out/headless`).
//! `cargo test` runs it too (the test below), into a temporary directory.

use std::error::Error;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use sylva_runtime::World;
use sylva_runtime::sylva_core::scene::Scene;
use sylva_runtime::sylva_gpu::GpuContext;
use sylva_runtime::sylva_gpu::render::{Camera, Lighting, RenderSettings, Renderer};

/// The scene: an aspen by Zioma's method with two copies, a palm by Akagi's, in gusty wind.
const SCENE: &str = r#"
wind = "gusty"
[output]
sim_rate = 60
[[tree]]
species = "quaking_aspen"
method = "zioma"
position = [-4.0, 0.0, 0.0]
copies = [{ position = [-10.0, 0.0, -12.0], yaw_deg = 50.0 }, { position = [6.0, 0.0, -16.0] }]
[[tree]]
species = "palm"
method = "akagi"
position = [4.0, 0.0, 2.0]
"#;

/// Image size.
const SIZE: (u32, u32) = (240, 160);

/// The application's own device: whatever adapter and limits it wants.
fn app_device() -> Result<(wgpu::Instance, wgpu::Adapter, wgpu::Device, wgpu::Queue), Box<dyn Error>> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("the application's device"),
        required_limits: adapter.limits(),
        ..Default::default()
    }))?;
    Ok((instance, adapter, device, queue))
}

/// Renders `frames` frames of the scene into `out` (`frame_0000.png`, …); returns the files.
fn run(
    device: (wgpu::Instance, wgpu::Adapter, wgpu::Device, wgpu::Queue),
    out: &Path,
    frames: usize,
) -> Result<Vec<PathBuf>, Box<dyn Error>> {
    let (instance, adapter, device, queue) = device;
    let ctx = Arc::new(GpuContext::from_wgpu(Some(instance), adapter, device, queue));
    let scene = Scene::from_toml(SCENE, "headless.rs scene", Path::new("."))?;
    let mut world = World::new(ctx.clone(), scene)?;
    let renderer = Renderer::new(&ctx, RenderSettings { width: SIZE.0, height: SIZE.1, msaa: 4, shadow_size: 1024 })?;
    let camera = Camera { eye: [0.0, 5.0, 24.0].into(), target: [0.0, 5.0, 0.0].into(), fov_y_deg: 45.0 };
    let globals = renderer.globals(&camera, &Lighting::default(), world.bounds());
    std::fs::create_dir_all(out)?;
    world.preroll(60);
    let mut written = Vec::new();
    for f in 0..frames {
        // A tenth of a second of simulation per frame, meshed and drawn in one submission.
        world.step(6)?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        world.record(&mut encoder);
        renderer.record(&ctx, &mut encoder, &globals, &world.draw_items());
        let rgba = renderer.read_image(&ctx, encoder)?;
        let image = image::RgbaImage::from_raw(SIZE.0, SIZE.1, rgba).ok_or("image size")?;
        let path = out.join(format!("frame_{f:04}.png"));
        let mut png = Vec::new();
        image.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)?;
        sylva_runtime::sylva_core::io::write_atomic(&path, |w| w.write_all(&png))?;
        written.push(path);
    }
    Ok(written)
}

fn main() -> Result<(), Box<dyn Error>> {
    let out = std::env::args().nth(1).map_or_else(|| PathBuf::from("out/headless"), PathBuf::from);
    for p in run(app_device()?, &out, 4)? {
        println!("wrote {}", p.display());
    }
    Ok(())
}

#[test]
fn headless_writes_frames_in_which_the_trees_move() {
    let device = match app_device() {
        Ok(d) => d,
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true" || v == "1") => {
            panic!("CI=true requires a GPU adapter (lavapipe will do): {e}")
        }
        Err(e) => return eprintln!("skipping the headless example: no GPU adapter ({e})"),
    };
    let dir = tempfile::tempdir().unwrap();
    let files = run(device, dir.path(), 3).unwrap();
    assert_eq!(files.len(), 3);
    let images: Vec<image::RgbaImage> = files.iter().map(|f| image::open(f).unwrap().to_rgba8()).collect();
    for (f, img) in files.iter().zip(&images) {
        assert_eq!(img.dimensions(), SIZE, "{}", f.display());
        let first = img.get_pixel(0, 0);
        assert!(img.pixels().any(|p| p != first), "{}: a blank frame", f.display());
    }
    // The wind moves the trees between frames.
    let changed = images[0].pixels().zip(images[2].pixels()).filter(|(a, b)| a != b).count();
    assert!(changed > 20, "only {changed} pixels changed between frames 0 and 2");
}
