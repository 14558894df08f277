//! The wgpu device, the one clear error when there is none, error scopes that turn a GPU
//! validation or out-of-memory error into one [`Error::Gpu`] line, and buffer read-back.

use std::sync::{Arc, Mutex};

use crate::error::{Error, Result};
use crate::gpu::pipeline_cache::DiskPipelineCache;
use crate::shader::{ErrorTarget, EyesPerDraw, ShaderOptions};

pub const NO_ADAPTER_HELP: &str = "no GPU adapter found: no Vulkan, Metal, DX12 or OpenGL driver is usable on this machine. \
Install a GPU driver, or Mesa's software Vulkan driver (lavapipe): `sudo apt-get install -y mesa-vulkan-drivers libvulkan1` \
on Debian/Ubuntu (scripts/test.sh does this for you). If WGPU_BACKEND is set, check that it names an available backend.";

/// How long a read-back waits for the GPU before it gives up with an error.
const READBACK_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(600);

pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
    pub features: wgpu::Features,
    /// How the error pass writes its target: R32Float where the adapter can render to it,
    /// else R32Uint bits. `TWISTER_ERROR_TARGET=uint` forces the latter (for tests).
    pub error_target: ErrorTarget,
    /// How the raster stage draws the two eyes: both in one multiview draw where the adapter
    /// has multiview (2 views or more) and is a hardware GPU, else a pass per eye.
    /// `TWISTER_MULTIVIEW=on|off` overrides the choice (where the adapter has multiview).
    pub eyes_per_draw: EyesPerDraw,
    /// The adapter the device was opened on (its format features: `targets::sample_counts`).
    pub adapter: wgpu::Adapter,
    /// GPU errors raised outside any error scope (kept instead of wgpu's default panic).
    uncaptured: Arc<Mutex<Vec<String>>>,
    /// The pipelines' cache on disk, where the adapter has one (saved when the device closes).
    pipeline_cache: Option<DiskPipelineCache>,
}

impl Drop for Gpu {
    fn drop(&mut self) {
        self.save_pipeline_cache();
    }
}

/// The texture format of an error target.
pub fn error_target_format(target: ErrorTarget) -> wgpu::TextureFormat {
    match target {
        ErrorTarget::Float => wgpu::TextureFormat::R32Float,
        ErrorTarget::UintBits => wgpu::TextureFormat::R32Uint,
    }
}

/// Mesa's device-select Vulkan layer prints `XDG_RUNTIME_DIR is invalid` twice on machines
/// without a desktop session; `NODEVICE_SELECT=1` turns the layer off (it only reorders
/// adapters). Set for this process before the first instance, unless the user set it.
fn quiet_device_select_layer() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        if std::env::var_os("NODEVICE_SELECT").is_none() && std::env::var_os("XDG_RUNTIME_DIR").is_none() {
            // SAFETY: called once, before wgpu (or anything else in twister) starts threads
            // that read the environment.
            unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
        }
    });
}

/// A wgpu error as one line.
fn one_line(e: &wgpu::Error) -> String {
    e.to_string().split_whitespace().collect::<Vec<_>>().join(" ")
}

impl Gpu {
    /// Opens the default adapter (respecting `WGPU_BACKEND`) with its full limits.
    pub fn new() -> Result<Gpu> {
        quiet_device_select_layer();
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        pollster::block_on(Self::new_async(instance, None))
    }

    /// Opens an adapter that can present to a window (the live window's), with the window's
    /// surface.
    pub fn for_window(
        display: Box<dyn wgpu::wgt::WgpuHasDisplayHandle>,
        window: impl Into<wgpu::SurfaceTarget<'static>>,
    ) -> Result<(Gpu, wgpu::Surface<'static>)> {
        quiet_device_select_layer();
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(display));
        let surface =
            instance.create_surface(window).map_err(|e| Error::NoGpu(format!("cannot draw into the window: {e}")))?;
        let gpu = pollster::block_on(Self::new_async(instance, Some(&surface)))?;
        Ok((gpu, surface))
    }

    /// Opens the adapter whose name contains `name` (any case), or the default one where `name`
    /// is None; an error listing the adapters there are where none matches.
    pub fn with_adapter(name: Option<&str>) -> Result<Gpu> {
        let Some(name) = name else { return Gpu::new() };
        quiet_device_select_layer();
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
        let names: Vec<String> =
            adapters.iter().map(|a| a.get_info()).map(|i| format!("{} ({:?})", i.name, i.backend)).collect();
        let wanted = name.to_lowercase();
        let Some(k) = names.iter().position(|n| n.to_lowercase().contains(&wanted)) else {
            let there = if names.is_empty() { "none".to_string() } else { names.join(", ") };
            return Err(Error::setting(
                "adapter",
                format!("no adapter's name contains {name:?}; the adapters: {there}"),
            ));
        };
        let adapter = adapters.into_iter().nth(k).expect("the position found");
        pollster::block_on(Self::from_adapter(adapter))
    }

    async fn new_async(instance: wgpu::Instance, surface: Option<&wgpu::Surface<'static>>) -> Result<Gpu> {
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                compatible_surface: surface,
                ..Default::default()
            })
            .await
            .map_err(|e| Error::NoGpu(format!("{NO_ADAPTER_HELP} ({e})")))?;
        Self::from_adapter(adapter).await
    }

    async fn from_adapter(adapter: wgpu::Adapter) -> Result<Gpu> {
        let info = adapter.get_info();
        let float_renderable = adapter
            .get_texture_format_features(wgpu::TextureFormat::R32Float)
            .allowed_usages
            .contains(wgpu::TextureUsages::RENDER_ATTACHMENT);
        let forced_uint = std::env::var("TWISTER_ERROR_TARGET").is_ok_and(|v| v == "uint");
        let error_target = if float_renderable && !forced_uint { ErrorTarget::Float } else { ErrorTarget::UintBits };
        let limits = adapter.limits();
        let multiview = adapter.features().contains(wgpu::Features::MULTIVIEW)
            && limits.max_multiview_view_count >= 2
            && match std::env::var("TWISTER_MULTIVIEW").as_deref() {
                Ok("off") => false,
                Ok("on") => true,
                // Lavapipe (Mesa 22.3, measured) drops or mixes a few pixels near triangle
                // edges in multiview draws when the machine is busy: a race in the driver that
                // makes frames differ from run to run. Software adapters draw a pass per eye.
                _ => info.device_type != wgpu::DeviceType::Cpu,
            };
        let eyes_per_draw = if multiview { EyesPerDraw::Both } else { EyesPerDraw::One };
        let wanted = wgpu::Features::TIMESTAMP_QUERY
            | wgpu::Features::MULTIVIEW
            | wgpu::Features::PIPELINE_CACHE
            | wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES;
        let features = adapter.features() & wanted;
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("twister"),
                required_features: features,
                required_limits: limits.clone(),
                ..Default::default()
            })
            .await
            .map_err(|e| Error::NoGpu(format!("the GPU adapter '{}' could not open a device: {e}", info.name)))?;
        let uncaptured = Arc::new(Mutex::new(Vec::new()));
        let sink = uncaptured.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            sink.lock().unwrap_or_else(|p| p.into_inner()).push(one_line(&e));
        }));
        let pipeline_cache = DiskPipelineCache::open(&device, &info);
        Ok(Gpu {
            device,
            queue,
            info,
            limits,
            features,
            error_target,
            eyes_per_draw,
            adapter,
            uncaptured,
            pipeline_cache,
        })
    }

    /// The pipeline cache for a pipeline about to be built (`cache` of its descriptor).
    pub fn pipeline_cache(&self) -> Option<&wgpu::PipelineCache> {
        self.pipeline_cache.as_ref().map(DiskPipelineCache::for_build)
    }

    /// Writes the pipeline cache to disk if pipelines were built since it was loaded (also done
    /// when the device closes).
    pub fn save_pipeline_cache(&self) {
        if let Some(cache) = &self.pipeline_cache {
            cache.save();
        }
    }

    /// What the generated shader modules depend on.
    pub fn shader_options(&self) -> ShaderOptions {
        ShaderOptions { error_target: self.error_target, eyes: self.eyes_per_draw }
    }

    /// "name (backend, device type; how the eyes are drawn)", for stats and logs.
    pub fn adapter_description(&self) -> String {
        let eyes = match self.eyes_per_draw {
            EyesPerDraw::Both => "both eyes per draw (multiview)",
            EyesPerDraw::One => "a pass per eye",
        };
        format!("{} ({:?}, {:?}; {eyes})", self.info.name, self.info.backend, self.info.device_type)
    }

    /// The largest buffer a stage can bind on this device, bytes.
    pub fn max_binding(&self) -> u64 {
        self.limits.max_storage_buffer_binding_size.min(self.limits.max_buffer_size)
    }

    /// Runs `f` inside validation and out-of-memory error scopes: a GPU error raised by the
    /// work becomes one `Error::Gpu` line naming `what`, instead of a panic.
    pub fn scoped<T>(&self, what: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let result = f();
        let invalid = pollster::block_on(validation.pop());
        let out_of_memory = pollster::block_on(oom.pop());
        if let Some(e) = out_of_memory.or(invalid) {
            return Err(Error::Gpu(format!("{what}: {}", one_line(&e))));
        }
        if let Some(e) = self.uncaptured.lock().unwrap_or_else(|p| p.into_inner()).drain(..).next() {
            return Err(Error::Gpu(format!("{what}: {e}")));
        }
        result
    }

    /// Blocks until the GPU has finished all submitted work.
    pub fn wait(&self) {
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
    }

    /// Reads a whole buffer (which must have MAP_READ usage) back to the CPU.
    pub fn read_buffer(&self, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
        self.read_mapped(buffer, |bytes| bytes.to_vec())
    }

    /// Maps a whole buffer (which must have MAP_READ usage) once the GPU is done with it and
    /// hands its bytes to `read`, which takes what it needs before the buffer is unmapped.
    pub fn read_mapped<R>(&self, buffer: &wgpu::Buffer, read: impl FnOnce(&[u8]) -> R) -> Result<R> {
        let mapped = Arc::new(Mutex::new(None));
        let slot = mapped.clone();
        buffer.map_async(wgpu::MapMode::Read, .., move |r| {
            *slot.lock().unwrap_or_else(|p| p.into_inner()) = Some(r);
        });
        // A wait can return before the work is done (lavapipe, rarely, on a busy machine: its
        // fence wait returns early): poll again until the mapping is done, within a bound.
        let deadline = std::time::Instant::now() + READBACK_TIMEOUT;
        let status = loop {
            self.wait();
            if let Some(status) = mapped.lock().unwrap_or_else(|p| p.into_inner()).take() {
                break status;
            }
            if std::time::Instant::now() > deadline {
                return Err(Error::Gpu(format!(
                    "reading back a buffer: the GPU did not finish within {} s",
                    READBACK_TIMEOUT.as_secs()
                )));
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        };
        if let Err(e) = status {
            return Err(Error::Gpu(format!("reading back a buffer: {e}")));
        }
        let data = {
            let mapped = buffer.get_mapped_range(..).map_err(|e| Error::Gpu(format!("reading back a buffer: {e}")))?;
            read(&mapped)
        };
        buffer.unmap();
        Ok(data)
    }

    /// Copies `size` bytes of `source` into a fresh readback buffer and returns them.
    pub fn download(&self, source: &wgpu::Buffer, size: u64) -> Result<Vec<u8>> {
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: size.max(4),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        if size > 0 {
            enc.copy_buffer_to_buffer(source, 0, &staging, 0, size);
        }
        self.queue.submit([enc.finish()]);
        let mut data = self.read_buffer(&staging)?;
        data.truncate(size as usize);
        Ok(data)
    }

    /// A storage buffer of `size` bytes (also a copy source and destination).
    pub fn storage_buffer(&self, label: &str, size: u64, extra: wgpu::BufferUsages) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(4),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST | extra,
            mapped_at_creation: false,
        })
    }

    /// A buffer holding `bytes` (16 zero bytes when empty: bindings may not be empty).
    pub fn init_buffer(&self, label: &str, bytes: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
        use wgpu::util::DeviceExt;
        let contents = if bytes.is_empty() { &[0u8; 16][..] } else { bytes };
        self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
    }

    /// A uniform buffer for a `T`, written with `queue.write_buffer` before each use.
    pub fn uniform_buffer<T: bytemuck::Pod>(&self, label: &str) -> wgpu::Buffer {
        self.params_buffer::<T>(label, wgpu::BufferUsages::UNIFORM)
    }

    /// A read-only storage buffer for a `T`, written likewise: parameters that lavapipe must not
    /// inline (the `subdivide` stage's, subdivide_bindings.wgsl).
    pub fn storage_params_buffer<T: bytemuck::Pod>(&self, label: &str) -> wgpu::Buffer {
        self.params_buffer::<T>(label, wgpu::BufferUsages::STORAGE)
    }

    fn params_buffer<T: bytemuck::Pod>(&self, label: &str, usage: wgpu::BufferUsages) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: std::mem::size_of::<T>() as u64,
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    /// Workgroups of `size` invocations for `count` items, as (x, y) within the device's
    /// per-dimension limit (a 2-D dispatch beyond it; shaders flatten `gid.x + gid.y·x·size`).
    pub fn workgroups(&self, count: u32, size: u32) -> (u32, u32) {
        let max = self.limits.max_compute_workgroups_per_dimension.max(1);
        let groups = count.div_ceil(size).max(1);
        if groups <= max {
            (groups, 1)
        } else {
            (max, groups.div_ceil(max))
        }
    }
}
