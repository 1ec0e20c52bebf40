//! Timing and the record of the machine: wall-clock and timestamp-query sampling, median
//! and spread, and the CPU's and GPU's copy bandwidth every row is set against.

use anyhow::Result;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// A timing: median and spread of the samples, in steps per second.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Rate {
    /// Median of the samples, steps/s.
    pub median: f64,
    /// Slowest sample, steps/s.
    pub min: f64,
    /// Fastest sample, steps/s.
    pub max: f64,
    /// Samples taken.
    pub samples: usize,
    /// Steps per sample.
    pub steps_per_sample: usize,
    /// How the samples were timed: `wall clock` or `timestamp queries`.
    pub clock: &'static str,
}

impl Rate {
    /// Milliseconds per step: [median, fastest, slowest].
    pub fn ms(&self) -> [f64; 3] {
        [1e3 / self.median, 1e3 / self.max, 1e3 / self.min]
    }
}

/// The machine a bench ran on.
#[derive(Debug, Clone, Serialize)]
pub struct Machine {
    /// CPU model name.
    pub cpu: String,
    /// Hardware threads available.
    pub cores: usize,
    /// rayon worker threads.
    pub threads: usize,
    /// GPU adapter, backend and driver (when the GPU was timed).
    pub gpu: Option<String>,
    /// Measured CPU copy bandwidth (read + write), bytes/s.
    pub cpu_bandwidth: f64,
    /// Measured GPU copy bandwidth (read + write), bytes/s: the faster of a buffer-to-buffer
    /// copy and a copy kernel ([`gpu_bandwidth`], [`gpu_probes`]).
    pub gpu_bandwidth: Option<f64>,
    /// The buffer-to-buffer copy's bandwidth alone, bytes/s.
    pub gpu_buffer_copy: Option<f64>,
    /// The copy kernel's bandwidth alone, bytes/s (with timestamp queries).
    pub gpu_kernel_copy: Option<f64>,
    /// GPU time of one dependent dispatch of a single workgroup, s (with timestamp queries):
    /// the floor each dispatch of a step pays.
    pub gpu_dispatch: Option<f64>,
    /// GPU time of that dispatch in a compute pass of its own, s.
    pub gpu_pass: Option<f64>,
    /// How GPU work is timed: `timestamp queries` or `wall clock`.
    pub gpu_clock: Option<&'static str>,
    /// UTC time of the run.
    pub date: String,
    /// The command line.
    pub command: String,
}

/// What every table's runner needs.
#[derive(Debug)]
pub struct Env<'a> {
    /// Small sizes only.
    pub quick: bool,
    /// Time budget per measurement, s.
    pub budget: f64,
    /// Whether to time the CPU.
    pub time_cpu: bool,
    /// The GPU, when it is timed.
    pub ctx: Option<&'static sylva_gpu::GpuContext>,
    /// Where the files go.
    pub out_dir: &'a Path,
    /// The machine record.
    pub machine: &'a Machine,
}

/// Times `f(n)` (n steps) by wall clock: one warm-up call, a step count that makes a sample
/// about a fifth of `budget`, then samples until the budget is spent (at least 3, at most
/// 15).
pub fn measure(budget: f64, mut f: impl FnMut(usize) -> Result<()>) -> Result<Rate> {
    sample(budget, |n| {
        let t0 = Instant::now();
        f(n)?;
        Ok((t0.elapsed().as_secs_f64(), false))
    })
}

/// Times GPU work as [`measure`] does; `f(n)` submits n steps (it need not wait). With
/// timestamp queries a sample is the GPU's time from the first submission to the end of the
/// last; without them, wall clock from the first submission to completion.
pub fn measure_gpu(budget: f64, ctx: &sylva_gpu::GpuContext, mut f: impl FnMut(usize) -> Result<()>) -> Result<Rate> {
    let timer = sylva_gpu::timer::GpuTimer::new(ctx);
    sample(budget, |n| {
        ctx.wait()?;
        let t0 = Instant::now();
        if let Some(t) = &timer {
            t.start(ctx);
        }
        f(n)?;
        let stamped = match &timer {
            Some(t) => {
                t.stop(ctx);
                t.read(ctx)?
            }
            None => None,
        };
        ctx.wait()?;
        Ok(match stamped {
            Some(d) => (d.as_secs_f64(), true),
            None => (t0.elapsed().as_secs_f64(), false),
        })
    })
}

/// Steps a GPU row's commands are counted over ([`count_gpu`]): one second at 60 Hz.
pub const COUNTED_STEPS: usize = 60;

/// The commands a GPU row records and submits per step, counted on the context over
/// [`COUNTED_STEPS`] steps run as the timed samples run them: what a step costs the driver
/// and the queue, beside the bytes it moves.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Commands {
    /// Compute dispatches per step.
    pub dispatches: f64,
    /// Compute passes per step.
    pub passes: f64,
    /// Bind groups created per step.
    pub bind_groups: f64,
    /// Queue submissions per step.
    pub submissions: f64,
}

/// Counts the commands of `f(COUNTED_STEPS)` ([`Commands`]); waits for the GPU.
pub fn count_gpu(ctx: &sylva_gpu::GpuContext, mut f: impl FnMut(usize) -> Result<()>) -> Result<Commands> {
    ctx.wait()?;
    let before = ctx.counts();
    f(COUNTED_STEPS)?;
    ctx.wait()?;
    let d = ctx.counts() - before;
    let per = |x: u64| x as f64 / COUNTED_STEPS as f64;
    Ok(Commands {
        dispatches: per(d.dispatches),
        passes: per(d.passes),
        bind_groups: per(d.bind_groups),
        submissions: per(d.submissions),
    })
}

/// The heading of the commands column.
pub const COMMANDS_HEADING: &str = "GPU dispatches / passes / bind groups / submissions per step";

/// A commands cell: `dispatches / passes / bind groups / submissions`, whole numbers plain.
pub fn commands_cell(c: Option<Commands>) -> String {
    let num = |x: f64| if x == x.round() { format!("{x:.0}") } else { format!("{x:.3}") };
    c.map_or("–".into(), |c| {
        format!("{} / {} / {} / {}", num(c.dispatches), num(c.passes), num(c.bind_groups), num(c.submissions))
    })
}

/// The sampling loop: `f(n)` runs n steps and returns (seconds, timed by timestamps).
fn sample(budget: f64, mut f: impl FnMut(usize) -> Result<(f64, bool)>) -> Result<Rate> {
    let one = f(1)?.0.max(1e-7);
    // A second probe with more steps, now that caches and pipelines are warm.
    let probe = ((budget / 20.0 / one) as usize).clamp(1, 100_000);
    let per = (f(probe)?.0 / probe as f64).max(1e-8);
    let n = ((budget / 5.0 / per) as usize).clamp(1, 1_000_000);
    let mut rates = Vec::new();
    let mut stamped = true;
    let start = Instant::now();
    while rates.len() < 3 || (start.elapsed().as_secs_f64() < budget && rates.len() < 15) {
        let (secs, s) = f(n)?;
        stamped &= s;
        rates.push(n as f64 / secs.max(1e-9));
    }
    rates.sort_by(f64::total_cmp);
    Ok(Rate {
        median: rates[rates.len() / 2],
        min: rates[0],
        max: rates[rates.len() - 1],
        samples: rates.len(),
        steps_per_sample: n,
        clock: if stamped { "timestamp queries" } else { "wall clock" },
    })
}

pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

/// Parallel copy of 64 MiB (best of 5): bytes read plus bytes written per second.
pub fn cpu_bandwidth() -> f64 {
    use rayon::prelude::*;
    let n = 16 << 20;
    let src = vec![1.0f32; n];
    let mut dst = vec![0.0f32; n];
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t0 = Instant::now();
        dst.par_chunks_mut(1 << 16).zip(src.par_chunks(1 << 16)).for_each(|(d, s)| d.copy_from_slice(s));
        best = best.min(t0.elapsed().as_secs_f64());
    }
    std::hint::black_box(&dst);
    2.0 * (n * 4) as f64 / best.max(1e-9)
}

/// Buffer-to-buffer copies on the GPU, eight of 64 MiB back and forth in one submission
/// (best of 5): bytes read plus written per second. Timed by timestamp queries around the
/// copies where the device has them (a fast card copies 64 MiB in tens of microseconds, about
/// what a submission and its wait cost), by wall clock from submission to completion if not.
pub fn gpu_bandwidth(ctx: &sylva_gpu::GpuContext) -> Result<f64> {
    const COPIES: u64 = 8;
    let bytes = 64u64 << 20;
    let make = |label| {
        ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes,
            usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    };
    let (a, b) = (make("bandwidth a"), make("bandwidth b"));
    let timer = sylva_gpu::timer::GpuTimer::new(ctx);
    let mut best = f64::INFINITY;
    for _ in 0..6 {
        let mut e = ctx.device.create_command_encoder(&Default::default());
        if let Some(t) = &timer {
            t.begin(&mut e);
        }
        for i in 0..COPIES {
            let (from, to) = if i % 2 == 0 { (&a, &b) } else { (&b, &a) };
            e.copy_buffer_to_buffer(from, 0, to, 0, bytes);
        }
        if let Some(t) = &timer {
            t.end(&mut e);
        }
        ctx.wait()?;
        let t0 = Instant::now();
        ctx.submit([e.finish()]);
        ctx.wait()?;
        let wall = t0.elapsed().as_secs_f64();
        let stamped = match &timer {
            Some(t) => t.read(ctx)?.map(|d| d.as_secs_f64()),
            None => None,
        };
        best = best.min(stamped.unwrap_or(wall));
    }
    Ok(2.0 * (COPIES * bytes) as f64 / best.max(1e-9))
}

/// The machine probes of `probe.wgsl` ([`GpuProbes`]), timed by timestamp queries. `None`
/// without timestamp queries: wall clock would time the submission, not the card.
pub fn gpu_probes(ctx: &sylva_gpu::GpuContext) -> Result<Option<GpuProbes>> {
    const DISPATCHES: u32 = 1000;
    let Some(timer) = sylva_gpu::timer::GpuTimer::new(ctx) else { return Ok(None) };
    let device = &ctx.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("bench probes"),
        source: wgpu::ShaderSource::Wgsl(include_str!("probe.wgsl").into()),
    });
    let pipeline = |entry| {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: None,
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    };
    let bytes = 64u64 << 20;
    let buffer = |label| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        })
    };
    let (src, dst) = (buffer("probe src"), buffer("probe dst"));
    let (copy, touch) = (pipeline("copy"), pipeline("touch"));
    let bind = |p: &wgpu::ComputePipeline, entries: &[(u32, &wgpu::Buffer)]| {
        let entries: Vec<_> = entries
            .iter()
            .map(|&(binding, b)| wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("probe"),
            layout: &p.get_bind_group_layout(0),
            entries: &entries,
        })
    };
    let (copy_group, touch_group) = (bind(&copy, &[(0, &src), (1, &dst)]), bind(&touch, &[(1, &dst)]));
    let groups = (bytes / 16).div_ceil(256) as u32;
    let (gx, gy) = (groups.min(32_768), groups.div_ceil(32_768));
    let time = |record: &dyn Fn(&mut wgpu::CommandEncoder)| -> Result<f64> {
        let mut best = f64::INFINITY;
        for _ in 0..6 {
            let mut e = device.create_command_encoder(&Default::default());
            record(&mut e);
            ctx.wait()?;
            timer.start(ctx);
            ctx.submit([e.finish()]);
            timer.stop(ctx);
            if let Some(d) = timer.read(ctx)? {
                best = best.min(d.as_secs_f64());
            }
        }
        Ok(best)
    };
    let touches = |pass: &mut wgpu::ComputePass<'_>, n: u32| {
        pass.set_pipeline(&touch);
        pass.set_bind_group(0, &touch_group, &[]);
        for _ in 0..n {
            pass.dispatch_workgroups(1, 1, 1);
        }
    };
    let copy_s = time(&|e| {
        let mut pass = e.begin_compute_pass(&Default::default());
        pass.set_pipeline(&copy);
        pass.set_bind_group(0, &copy_group, &[]);
        pass.dispatch_workgroups(gx, gy, 1);
    })?;
    let touch_s = time(&|e| touches(&mut e.begin_compute_pass(&Default::default()), DISPATCHES))?;
    let pass_s = time(&|e| {
        for _ in 0..DISPATCHES {
            touches(&mut e.begin_compute_pass(&Default::default()), 1);
        }
    })?;
    if !(copy_s.is_finite() && touch_s.is_finite() && pass_s.is_finite()) {
        return Ok(None);
    }
    let n = DISPATCHES as f64;
    Ok(Some(GpuProbes { kernel_copy: 2.0 * bytes as f64 / copy_s.max(1e-9), dispatch: touch_s / n, pass: pass_s / n }))
}

/// What [`gpu_probes`] measures.
#[derive(Debug, Clone, Copy)]
pub struct GpuProbes {
    /// A copy kernel's read + write bandwidth over 64 MiB, bytes/s (best of 5).
    pub kernel_copy: f64,
    /// GPU time of one dependent dispatch of a single workgroup, a thousand in one pass with
    /// a barrier between each, s (best of 5).
    pub dispatch: f64,
    /// The same dispatch in a compute pass of its own, a thousand passes, s (best of 5): what
    /// each pass adds, beside [`Self::dispatch`].
    pub pass: f64,
}

pub fn rate_cell(r: Option<Rate>) -> String {
    r.map_or("–".into(), |r| format!("{:.0} ({:.0}–{:.0})", r.median, r.min, r.max))
}

pub fn ratio_cell(r: Option<Rate>, paper: f64) -> String {
    r.map_or("–".into(), |r| format!("{:.2}", r.median / paper))
}

pub fn frac_cell(f: Option<f64>) -> String {
    f.map_or("–".into(), |f| format!("{:.1} %", 100.0 * f))
}

/// The GPU's measured figures in words: copy bandwidth (and its two measurements, when
/// the copy kernel was timed) and the dependent-dispatch floor.
pub fn gpu_figures(m: &Machine) -> String {
    let gb = |b: f64| format!("{:.1} GB/s", b / 1e9);
    let mut s = format!("copy bandwidth {}", m.gpu_bandwidth.map_or("–".into(), gb));
    if let (Some(b), Some(k)) = (m.gpu_buffer_copy, m.gpu_kernel_copy) {
        s += &format!(" (buffer copy {}, copy kernel {})", gb(b), gb(k));
    }
    if let Some(d) = m.gpu_dispatch {
        s += &format!(", dependent dispatch {:.1} µs", d * 1e6);
    }
    if let Some(p) = m.gpu_pass {
        s += &format!(" ({:.1} µs in a pass of its own)", p * 1e6);
    }
    s
}

/// The heading and machine paragraph every table's Markdown starts with.
pub fn markdown_head(title: &str, table: &str, m: &Machine) -> String {
    let mut s = format!("### {title} ({table})\n\n");
    s += &format!(
        "Machine: {} ({} threads of {} cores), CPU copy bandwidth {:.1} GB/s",
        m.cpu,
        m.threads,
        m.cores,
        m.cpu_bandwidth / 1e9
    );
    if let Some(g) = &m.gpu {
        s += &format!("; GPU {g}, {}, timed by {}", gpu_figures(m), m.gpu_clock.unwrap_or("wall clock"));
    }
    s += &format!(".\nDate {}. Command `{}`.\n\n", m.date, m.command);
    s
}

/// Writes `bytes` to `path` completely or not at all.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    sylva_core::io::write_atomic(path, |w| w.write_all(bytes))
        .map_err(|e| anyhow::anyhow!("writing {}: {e}", path.display()))
}
