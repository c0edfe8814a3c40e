//! The Vulkan device glint renders on.

use sha2::{Digest, Sha256};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// Why no GPU could be used.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct GpuUnavailable(pub String);

/// A Vulkan device and its queue, with the errors wgpu reports asynchronously.
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// The adapter the device was opened on (a window asks it for surface capabilities).
    pub adapter: wgpu::Adapter,
    pub adapter_info: wgpu::AdapterInfo,
    pub features: wgpu::Features,
    errors: Arc<Mutex<Vec<String>>>,
    /// Compute pipelines made on this device, by [`PipelineKey`]: a second renderer of the same
    /// kernel (the test suite's many renders, the viewer's reloads, Python's renders) reuses
    /// the pipeline instead of translating and compiling the kernel again (lavapipe: seconds).
    pipelines: Mutex<HashMap<PipelineKey, Arc<OnceLock<CachedPipeline>>>>,
}

type CachedPipeline = Option<(wgpu::BindGroupLayout, wgpu::ComputePipeline)>;

/// What a compute pipeline is made of: a digest of the kernel's source, its entry point and
/// its bind group layout's entries.
type PipelineKey = [u8; 32];

fn pipeline_key(
    source: &str,
    entry_point: &str,
    layout_entries: &[wgpu::BindGroupLayoutEntry],
) -> PipelineKey {
    let mut digest = Sha256::new();
    for part in [source, entry_point, &format!("{layout_entries:?}")] {
        digest.update((part.len() as u64).to_le_bytes());
        digest.update(part.as_bytes());
    }
    digest.finalize().into()
}

/// Creates the folder Mesa keeps its shader cache in, before the Vulkan devices are enumerated
/// (when lavapipe opens its cache), and warns when that fails. Mesa creates only the last
/// folder of the path and otherwise disables the cache, and lavapipe then recompiles the
/// kernel for every dispatch: a mesh scene, one sample per dispatch, spent minutes per sample
/// in LLVM. The folder is Mesa's: `MESA_SHADER_CACHE_DIR`, else `$XDG_CACHE_HOME`, else
/// `$HOME/.cache`. Other drivers ignore it.
fn prepare_mesa_shader_cache() {
    use std::env::var_os;
    use std::path::PathBuf;
    if var_os("MESA_SHADER_CACHE_DISABLE").is_some() || var_os("MESA_DISK_CACHE_DISABLE").is_some()
    {
        return;
    }
    let folder = match (
        var_os("MESA_SHADER_CACHE_DIR"),
        var_os("XDG_CACHE_HOME"),
        var_os("HOME"),
    ) {
        (Some(dir), _, _) => PathBuf::from(dir),
        (None, Some(cache), _) => PathBuf::from(cache),
        (None, None, Some(home)) => PathBuf::from(home).join(".cache"),
        (None, None, None) => return,
    };
    if let Err(e) = std::fs::create_dir_all(&folder) {
        crate::errln!(
            "glint: warning: cannot create the shader cache folder {} ({e}); lavapipe will \
             recompile the kernel for every dispatch (set MESA_SHADER_CACHE_DIR to a writable folder)",
            folder.display()
        );
    }
}

impl GpuContext {
    /// Opens the first Vulkan adapter (high performance preferred). Only Vulkan is enabled:
    /// with every backend on, a machine without a Vulkan driver silently gets an OpenGL
    /// adapter whose output differs.
    pub fn new() -> Result<GpuContext, GpuUnavailable> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::VULKAN;
        desc.flags = wgpu::InstanceFlags::empty().with_env();
        Self::with_instance(&wgpu::Instance::new(desc), None)
    }

    /// Opens a device on `instance`, able to present to `surface` when one is given.
    pub fn with_instance(
        instance: &wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<GpuContext, GpuUnavailable> {
        prepare_mesa_shader_cache();
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            compatible_surface: surface,
            ..Default::default()
        }))
        .map_err(|e| GpuUnavailable(format!("no Vulkan device found ({e})")))?;
        let adapter_info = adapter.get_info();
        if adapter_info.backend != wgpu::Backend::Vulkan {
            return Err(GpuUnavailable(format!(
                "adapter {} uses {:?}, not Vulkan",
                adapter_info.name, adapter_info.backend
            )));
        }
        // wgpu's default limits are below what lavapipe and desktop GPUs offer (e.g. the
        // 128 MiB storage binding the accumulation buffer may need): ask for the adapter's own,
        // acceleration-structure limits included (lavapipe allows 2²⁴ − 1 primitives per BLAS,
        // below wgpu's minimum defaults for ray queries).
        // Ray queries where the adapter has them, for the hardware traversal (--traversal).
        let features = adapter.features()
            & (wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::EXPERIMENTAL_RAY_QUERY);
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("glint"),
            required_features: features,
            required_limits: limits.clone().using_acceleration_structure_values(limits),
            // SAFETY: the one experimental feature asked for is ray queries, used only by the
            // hardware traversal's kernel variant and its acceleration structure
            // (src/gpu/acceleration.rs), tested against the software traversal
            // (tests/suite/hardware_traversal.rs).
            experimental_features: if features.contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY) {
                unsafe { wgpu::ExperimentalFeatures::enabled() }
            } else {
                wgpu::ExperimentalFeatures::disabled()
            },
            ..Default::default()
        }))
        .map_err(|e| GpuUnavailable(format!("cannot open {}: {e}", adapter_info.name)))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        // wgpu's default handler panics; a render reports the error instead.
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            sink.lock().unwrap().push(e.to_string());
        }));
        Ok(GpuContext {
            device,
            queue,
            adapter,
            adapter_info,
            features,
            errors,
            pipelines: Mutex::new(HashMap::new()),
        })
    }

    /// The bind group layout and compute pipeline for `entry_point` of the WGSL `source` with
    /// one bind group of `layout_entries`: made once per device, then shared. Bind groups for
    /// it must be made with the layout returned here.
    pub fn compute_pipeline(
        &self,
        label: &str,
        source: &str,
        entry_point: &str,
        layout_entries: &[wgpu::BindGroupLayoutEntry],
    ) -> (wgpu::BindGroupLayout, wgpu::ComputePipeline) {
        let key = pipeline_key(source, entry_point, layout_entries);
        // The map is locked only to find the slot: different kernels compile in parallel,
        // and two threads asking for the same kernel compile it once.
        let slot = self
            .pipelines
            .lock()
            .unwrap()
            .entry(key)
            .or_default()
            .clone();
        let make = || {
            let errors_before = self.errors.lock().unwrap().len();
            let layout = self
                .device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some(label),
                    entries: layout_entries,
                });
            let module = self
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(label),
                    source: wgpu::ShaderSource::Wgsl(source.into()),
                });
            let pipeline = super::binding::compute_pipeline(
                &self.device,
                label,
                &layout,
                &module,
                entry_point,
            );
            let refused = self.errors.lock().unwrap().len() != errors_before;
            (layout, pipeline, refused)
        };
        if let Some(made) = slot.get_or_init(|| {
            let (layout, pipeline, refused) = make();
            // A pipeline the device refused is not kept: the next caller gets the error again.
            (!refused).then_some((layout, pipeline))
        }) {
            return made.clone();
        }
        let (layout, pipeline, _) = make();
        (layout, pipeline)
    }

    /// The first error the device reported since the last call, if any.
    pub fn take_error(&self) -> Option<String> {
        let mut errors = self.errors.lock().unwrap();
        let first = errors.first().cloned();
        errors.clear();
        first
    }

    /// e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`.
    pub fn device_name(&self) -> String {
        self.adapter_info.name.clone()
    }

    pub fn backend_name(&self) -> String {
        format!("{:?}", self.adapter_info.backend).to_lowercase()
    }

    /// Maps a MAP_READ buffer (after the copies into it were submitted), waits for the GPU, and
    /// hands its bytes to `read`.
    pub fn read_mapped<T>(
        &self,
        buffer: &wgpu::Buffer,
        read: impl FnOnce(&[u8]) -> T,
    ) -> anyhow::Result<T> {
        let slice = buffer.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.wait_idle()?;
        rx.recv()
            .map_err(|_| anyhow::anyhow!("GPU readback was dropped"))?
            .map_err(|e| anyhow::anyhow!("GPU readback failed: {e}"))?;
        let value = {
            let view = slice
                .get_mapped_range()
                .map_err(|e| anyhow::anyhow!("GPU readback failed: {e}"))?;
            read(&view)
        };
        buffer.unmap();
        Ok(value)
    }

    /// Whether the device traces with ray queries (the hardware traversal can run).
    pub fn has_ray_queries(&self) -> bool {
        self.features
            .contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY)
    }

    /// Blocks until all submitted work is done.
    pub fn wait_idle(&self) -> anyhow::Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| anyhow::anyhow!("GPU wait failed: {e}"))?;
        match self.take_error() {
            Some(e) => Err(anyhow::anyhow!("GPU error: {e}")),
            None => Ok(()),
        }
    }
}
