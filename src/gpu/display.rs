//! The `display` stage on the GPU (twin `cpu::display`): draws what the live window shows of a
//! frame ([`crate::core::display`]) into a target (the window's surface, or a texture in the
//! tests), from the frame's colour in a storage buffer ([`ShownFrame`]): the renderer leaves
//! it there instead of reading it back (`Renderer::render_shown`).

use std::sync::Mutex;

use crate::core::display::DisplayMode;
use crate::core::frame::EyeImage;
use crate::core::panoramas::registry::PANORAMAS;
use crate::encoding::types::DisplayParams;
use crate::gpu::device::Gpu;
use crate::gpu::stages::GpuStage;
use crate::shader::DISPLAY;

/// A drawn frame's colour on the GPU: both eyes' sRGB bytes (or one image's), packed RGBA in
/// words, each layer `height` rows of `row_texels`.
#[derive(Clone, Debug)]
pub struct ShownFrame {
    pub texels: wgpu::Buffer,
    pub width: u32,
    pub height: u32,
    pub row_texels: u32,
    pub layers: u32,
}

impl ShownFrame {
    /// Images of one size uploaded (the error heatmap; a frame box-filtered on the CPU).
    pub fn upload(gpu: &Gpu, images: &[&EyeImage]) -> ShownFrame {
        let (width, height) = (images[0].width, images[0].height);
        let bytes: Vec<u8> = images.iter().flat_map(|i| i.rgba.iter().copied()).collect();
        let texels = gpu.init_buffer("shown frame", &bytes, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
        ShownFrame { texels, width, height, row_texels: width, layers: images.len() as u32 }
    }
}

/// Where the display draws: a view of a texture (the window's surface) and its format.
pub struct DisplayTarget<'a> {
    pub view: &'a wgpu::TextureView,
    pub format: wgpu::TextureFormat,
}

/// The stage's layouts, its parameters' buffer and a pipeline per target format.
pub struct DisplayStage {
    stage: GpuStage,
    params: wgpu::Buffer,
    /// Bound where there is no overlay.
    no_overlay: wgpu::Buffer,
    /// By target format and the panoramas compiled in (0: no look-around).
    pipelines: Mutex<Vec<((wgpu::TextureFormat, u32), wgpu::RenderPipeline)>>,
}

impl DisplayStage {
    pub fn new(gpu: &Gpu) -> DisplayStage {
        DisplayStage {
            stage: GpuStage::new(gpu, &DISPLAY),
            params: gpu.uniform_buffer::<DisplayParams>("display params"),
            no_overlay: gpu.init_buffer("no overlay", &[0u8; 4], wgpu::BufferUsages::STORAGE),
            pipelines: Mutex::new(Vec::new()),
        }
    }

    /// The pipeline for a target format and the panoramas a look-around draws (`PANORAMAS`'
    /// bits; 0: the modes without the projection).
    fn pipeline(&self, gpu: &Gpu, format: wgpu::TextureFormat, panoramas: u32) -> wgpu::RenderPipeline {
        let mut pipelines = self.pipelines.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, p)) = pipelines.iter().find(|(key, _)| *key == (format, panoramas)) {
            return p.clone();
        }
        let module = self.stage.module(gpu, None);
        let constants = [("LOOK", (panoramas != 0) as u32 as f64), ("PANORAMAS", panoramas.max(1) as f64)];
        let options = wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
        let pipeline = gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("display"),
            layout: Some(self.stage.draw_layout()),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_main"),
                compilation_options: options.clone(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some("fs_main"),
                compilation_options: options,
                targets: &[Some(format.into())],
            }),
            multiview_mask: None,
            cache: gpu.pipeline_cache(),
        });
        pipelines.push(((format, panoramas), pipeline.clone()));
        pipeline
    }

    /// Records the display of `frame` with `params` into `target`, with the overlay's texels
    /// where `params.overlay` places one.
    pub fn draw(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        target: DisplayTarget,
        params: &DisplayParams,
        frame: &ShownFrame,
        overlay: Option<&wgpu::Buffer>,
    ) {
        let look = DisplayMode::from_code(params.mode).is_some_and(|m| m.is_look());
        let panoramas = match PANORAMAS.get(params.projection.panorama as usize) {
            Some(model) if look => model.shader_bits(),
            _ => 0,
        };
        let pipeline = self.pipeline(gpu, target.format, panoramas);
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(params));
        let overlay = overlay.unwrap_or(&self.no_overlay);
        let bind_group = self.stage.bind_group(gpu, None, 0, &[&self.params, &frame.texels, overlay]);
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("display"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target.view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
