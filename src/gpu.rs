//! The wgpu device, and the one clear error when there is none.

use std::fmt;

/// No usable GPU driver, or the device could not be opened.
#[derive(Debug)]
pub struct GpuError(pub String);

impl fmt::Display for GpuError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for GpuError {}

pub const NO_ADAPTER_HELP: &str = "no GPU adapter found: no Vulkan, Metal, DX12 or OpenGL driver is usable on this machine. \
Install a GPU driver, or Mesa's software Vulkan driver (lavapipe): `sudo apt-get install -y mesa-vulkan-drivers libvulkan1` \
on Debian/Ubuntu (scripts/test.sh does this for you). If WGPU_BACKEND is set, check that it names an available backend.";

pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
    pub features: wgpu::Features,
    /// How the error pass writes its target: R32Float where the adapter can render to it,
    /// else R32Uint bits. `TWISTER_ERROR_TARGET=uint` forces the latter (for tests).
    pub error_target: crate::shaders::ErrorTarget,
}

impl Gpu {
    /// Opens the default adapter (respecting `WGPU_BACKEND`) with its full limits.
    pub fn new() -> Result<Gpu, GpuError> {
        pollster::block_on(Self::new_async())
    }

    async fn new_async() -> Result<Gpu, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                ..Default::default()
            })
            .await
            .map_err(|e| GpuError(format!("{NO_ADAPTER_HELP} ({e})")))?;
        let info = adapter.get_info();
        let float_renderable = adapter
            .get_texture_format_features(wgpu::TextureFormat::R32Float)
            .allowed_usages
            .contains(wgpu::TextureUsages::RENDER_ATTACHMENT);
        let forced_uint = std::env::var("TWISTER_ERROR_TARGET").is_ok_and(|v| v == "uint");
        let error_target = if float_renderable && !forced_uint {
            crate::shaders::ErrorTarget::Float
        } else {
            crate::shaders::ErrorTarget::UintBits
        };
        let limits = adapter.limits();
        let wanted = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        let features = adapter.features() & wanted;
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("twister"),
                required_features: features,
                required_limits: limits.clone(),
                ..Default::default()
            })
            .await
            .map_err(|e| GpuError(format!("the GPU adapter '{}' could not open a device: {e}", info.name)))?;
        Ok(Gpu { device, queue, info, limits, features, error_target })
    }

    /// "name (backend, device type)", for stats and logs.
    pub fn adapter_description(&self) -> String {
        format!("{} ({:?}, {:?})", self.info.name, self.info.backend, self.info.device_type)
    }

    /// Blocks until the GPU has finished all submitted work.
    pub fn wait(&self) {
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
    }

    /// Reads a whole buffer (which must have MAP_READ usage) back to the CPU.
    pub fn read_buffer(&self, buffer: &wgpu::Buffer) -> Vec<u8> {
        buffer.map_async(wgpu::MapMode::Read, .., |r| r.expect("mapping a readback buffer"));
        self.wait();
        let data = buffer.get_mapped_range(..).expect("mapped range").to_vec();
        buffer.unmap();
        data
    }

    /// Copies `size` bytes of `source` into a fresh readback buffer and returns them.
    pub fn download(&self, source: &wgpu::Buffer, size: u64) -> Vec<u8> {
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
        let mut data = self.read_buffer(&staging);
        data.truncate(size as usize);
        data
    }
}
