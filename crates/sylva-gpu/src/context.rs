//! The GPU context: instance, adapter, device and queue.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};

/// Errors setting up or using the GPU.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter matched.
    #[error(
        "no GPU adapter found ({0}). Sylva needs a Vulkan, Metal or DX12 driver; on a machine \
         without a GPU install Mesa's software rasteriser (Debian/Ubuntu: \
         `apt-get install mesa-vulkan-drivers libvulkan1`) and set WGPU_BACKEND=vulkan"
    )]
    NoAdapter(String),
    /// The adapter refused the device.
    #[error("the GPU adapter `{adapter}` refused a device: {message}")]
    Device { adapter: String, message: String },
    /// Waiting for the GPU failed.
    #[error("waiting for the GPU failed: {0}")]
    Poll(String),
    /// Mapping a buffer for readback failed.
    #[error("reading back a GPU buffer failed: {0}")]
    Map(String),
    /// The shared context could not be set up (the first attempt's error, kept).
    #[error("{0}")]
    Unavailable(String),
    /// An input is larger than the device allows.
    #[error("{what}: {bytes} bytes exceeds the device's limit of {limit} bytes")]
    TooLarge { what: &'static str, bytes: u64, limit: u64 },
}

/// How to choose the adapter.
#[derive(Debug, Clone, Default)]
pub struct GpuOptions {
    /// Prefer a high-performance (discrete) adapter.
    pub high_performance: bool,
}

/// What adapter was chosen, for reports and benchmark records.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AdapterSummary {
    /// Adapter name, e.g. `llvmpipe (LLVM 15.0.6, 256 bits)` or `NVIDIA H100`.
    pub name: String,
    /// Backend, e.g. `Vulkan`.
    pub backend: String,
    /// Device type, e.g. `Cpu`, `DiscreteGpu`.
    pub device_type: String,
    /// Driver name and version.
    pub driver: String,
}

impl std::fmt::Display for AdapterSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} ({}, {}, driver {})", self.name, self.backend, self.device_type, self.driver)
    }
}

/// The commands Sylva's kernels recorded and submitted on a context, counted as they are
/// made ([`GpuContext::counts`]): the work model of `sylva bench` divides a run's difference
/// by its steps. Each dispatch, compute pass and bind group costs the driver time on the CPU
/// and, between dependent dispatches, a barrier on the GPU; each submission a trip through
/// the queue.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GpuCounts {
    /// Compute dispatches recorded.
    pub dispatches: u64,
    /// Compute passes begun.
    pub passes: u64,
    /// Bind groups created for compute kernels.
    pub bind_groups: u64,
    /// Command submissions to the queue.
    pub submissions: u64,
}

impl std::ops::Sub for GpuCounts {
    type Output = GpuCounts;
    fn sub(self, rhs: Self) -> Self {
        Self {
            dispatches: self.dispatches - rhs.dispatches,
            passes: self.passes - rhs.passes,
            bind_groups: self.bind_groups - rhs.bind_groups,
            submissions: self.submissions - rhs.submissions,
        }
    }
}

/// The running totals behind [`GpuCounts`].
#[derive(Debug, Default)]
pub(crate) struct Counters {
    pub(crate) dispatches: AtomicU64,
    pub(crate) passes: AtomicU64,
    pub(crate) bind_groups: AtomicU64,
    submissions: AtomicU64,
}

impl Counters {
    pub(crate) fn add(counter: &AtomicU64) {
        counter.fetch_add(1, Ordering::Relaxed);
    }
}

/// A device and its queue, with the adapter it came from.
#[derive(Debug)]
pub struct GpuContext {
    /// The instance (a window's surface must come from it); `None` for a device an
    /// application handed over without its instance.
    pub instance: Option<wgpu::Instance>,
    /// The adapter.
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// The queue.
    pub queue: wgpu::Queue,
    /// Adapter report.
    pub summary: AdapterSummary,
    /// Whether kernels can be timed with timestamp queries.
    pub timestamps: bool,
    /// The device's subgroup size, when it has subgroup operations and one size (its
    /// minimum and maximum agree, a power of two up to 64): kernels with a subgroup path use
    /// it ([`crate::methods::hsm::GpuHsm`]'s stage 1).
    pub subgroup_size: Option<u32>,
    /// Compiled kernels by name and pipeline constants: each is compiled once per context
    /// (see [`crate::kernel::Kernel::cached`]).
    pub(crate) kernels: std::sync::Mutex<std::collections::HashMap<KernelKey, std::sync::Arc<crate::kernel::Kernel>>>,
    pub(crate) counters: Counters,
}

/// A compiled kernel's name and its pipeline constants (name, value bits).
pub(crate) type KernelKey = (&'static str, Vec<(String, u64)>);

impl GpuContext {
    /// Creates a context. The instance reads the environment (`WGPU_BACKEND=vulkan` makes a
    /// missing Vulkan driver an error instead of a silent fallback to another backend).
    pub fn new(opts: &GpuOptions) -> Result<Self, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let power_preference = if opts.high_performance {
            wgpu::PowerPreference::HighPerformance
        } else {
            wgpu::PowerPreference::from_env().unwrap_or_default()
        };
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let summary = AdapterSummary {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend),
            device_type: format!("{:?}", info.device_type),
            driver: format!("{} {}", info.driver, info.driver_info).trim().to_string(),
        };
        // Timestamp queries to time kernels, subgroup operations for HSM's stage 1: each when
        // the adapter has it.
        let required_features = adapter.features() & (wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::SUBGROUP);
        // The adapter's own limits: kernels need large storage buffers and, on some
        // adapters, workgroups above the 256-thread default.
        let required_limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("sylva"),
            required_features,
            required_limits,
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| GpuError::Device { adapter: summary.name.clone(), message: e.to_string() })?;
        Ok(Self::from_wgpu(Some(instance), adapter, device, queue))
    }

    /// A context on an application's own device, so an engine and Sylva share it. Kernels
    /// respect the device's limits (a large tree may need the adapter's, not wgpu's
    /// defaults: a buffer beyond them is refused with [`GpuError::TooLarge`]); timestamp
    /// queries are used when the device was created with them.
    pub fn from_wgpu(
        instance: Option<wgpu::Instance>,
        adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> Self {
        let info = adapter.get_info();
        let summary = AdapterSummary {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend),
            device_type: format!("{:?}", info.device_type),
            driver: format!("{} {}", info.driver, info.driver_info).trim().to_string(),
        };
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let subgroup_size = (device.features().contains(wgpu::Features::SUBGROUP)
            && info.subgroup_min_size == info.subgroup_max_size
            && info.subgroup_min_size.is_power_of_two()
            && info.subgroup_min_size <= 64)
            .then_some(info.subgroup_min_size);
        Self {
            instance,
            adapter,
            device,
            queue,
            summary,
            timestamps,
            subgroup_size,
            kernels: Default::default(),
            counters: Default::default(),
        }
    }

    /// One context shared by the whole process (tests, benchmarks, the CLI): created on
    /// first use, reused after.
    pub fn shared() -> Result<&'static GpuContext, GpuError> {
        Ok(Self::shared_slot()?)
    }

    /// [`Self::shared`] as a handle others can keep ([`Arc`]).
    pub fn shared_arc() -> Result<Arc<GpuContext>, GpuError> {
        Ok(Self::shared_slot()?.clone())
    }

    fn shared_slot() -> Result<&'static Arc<GpuContext>, GpuError> {
        static SHARED: OnceLock<Result<Arc<GpuContext>, String>> = OnceLock::new();
        match SHARED.get_or_init(|| GpuContext::new(&GpuOptions::default()).map(Arc::new).map_err(|e| e.to_string())) {
            Ok(c) => Ok(c),
            Err(e) => Err(GpuError::Unavailable(e.clone())),
        }
    }

    /// Submits command buffers to the queue, counted in [`Self::counts`].
    pub fn submit<I: IntoIterator<Item = wgpu::CommandBuffer>>(&self, commands: I) -> wgpu::SubmissionIndex {
        Counters::add(&self.counters.submissions);
        self.queue.submit(commands)
    }

    /// The commands recorded and submitted on this context so far, by every user of it.
    pub fn counts(&self) -> GpuCounts {
        let c = &self.counters;
        GpuCounts {
            dispatches: c.dispatches.load(Ordering::Relaxed),
            passes: c.passes.load(Ordering::Relaxed),
            bind_groups: c.bind_groups.load(Ordering::Relaxed),
            submissions: c.submissions.load(Ordering::Relaxed),
        }
    }

    /// Blocks until all submitted work has finished.
    pub fn wait(&self) -> Result<(), GpuError> {
        self.device.poll(wgpu::PollType::wait_indefinitely()).map(|_| ()).map_err(|e| GpuError::Poll(e.to_string()))
    }
}
