//! The `shadow` stage on the GPU (maths in `core::shading::shadow`, twin `cpu::shadow`): each of a frame's
//! shadow maps drawn from its light (the scene's own triangles, a render pass per map into a
//! depth texture of its size) and copied into the scene's depth buffer, group 1's binding 7, which the
//! drawing stages read. The maps are drawn again only when they change (another view or other
//! lights); a frame without maps draws nothing.

use std::mem::offset_of;
use std::sync::OnceLock;

use glam::Mat4;

use crate::core::scenes::scene::SceneVertex;
use crate::core::shading::shadow::GpuShadowMap;
use crate::encoding::types::ShadowParams;
use crate::error::{Error, Result};
use crate::gpu::device::Gpu;
use crate::gpu::scene::{GpuScene, GpuShadows};
use crate::gpu::stages::GpuStage;
use crate::gpu::targets::DEPTH_FORMAT;
use crate::shader::SHADOW;

/// The `shadow` stage: its layouts and pipelines, depth only, and with `fs_mask` (scenes whose materials can
/// discard), each made when first needed.
pub(crate) struct ShadowStage {
    pub stage: GpuStage,
    pipelines: [OnceLock<wgpu::RenderPipeline>; 2],
}

impl ShadowStage {
    pub fn new(gpu: &Gpu) -> ShadowStage {
        ShadowStage { stage: GpuStage::new(gpu, &SHADOW), pipelines: [OnceLock::new(), OnceLock::new()] }
    }

    pub fn pipeline(&self, gpu: &Gpu, masked: bool) -> &wgpu::RenderPipeline {
        self.pipelines[masked as usize].get_or_init(|| {
            use wgpu::VertexFormat::{Float32x2, Float32x3, Float32x4, Uint32};
            let attribute = |format, offset: usize, shader_location| wgpu::VertexAttribute {
                format,
                offset: offset as u64,
                shader_location,
            };
            let attributes = [
                attribute(Float32x3, offset_of!(SceneVertex, position), 0),
                attribute(Float32x4, std::mem::offset_of!(SceneVertex, color), 1),
                attribute(Float32x2, std::mem::offset_of!(SceneVertex, uv), 2),
                attribute(Uint32, std::mem::offset_of!(SceneVertex, material), 3),
            ];
            let buffers = [Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<SceneVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &attributes,
            })];
            gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("shadow"),
                layout: Some(self.stage.draw_layout()),
                vertex: wgpu::VertexState {
                    module: self.stage.module(gpu, None),
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: masked.then(|| wgpu::FragmentState {
                    module: self.stage.module(gpu, None),
                    entry_point: Some("fs_mask"),
                    compilation_options: Default::default(),
                    targets: &[],
                }),
                multiview_mask: None,
                cache: gpu.pipeline_cache(),
            })
        })
    }
}

/// The depths of a scene's shadow maps as the last frame drew them (`bytes` of them).
pub fn shadow_depths(gpu: &Gpu, scene: &GpuScene, bytes: u64) -> Result<Vec<f32>> {
    let depths = scene.shadows.lock().unwrap_or_else(|e| e.into_inner()).depths.clone();
    Ok(bytemuck::cast_slice(&gpu.download(&depths, bytes)?).to_vec())
}

impl ShadowStage {
    /// Draws `maps` (the frame's, seen through `view`) into `scene`'s shadow depths, unless they
    /// hold them already. Fails with one line where the maps do not fit the device.
    pub fn draw_maps(&self, gpu: &Gpu, scene: &GpuScene, view: Mat4, maps: &[GpuShadowMap]) -> Result<()> {
        let Some(size) = maps.iter().map(|m| m.size).max() else {
            return Ok(());
        };
        let wanted: Vec<([[f32; 4]; 4], u32)> =
            maps.iter().map(|m| ((m.matrix() * view).to_cols_array_2d(), m.size)).collect();
        let mut shadows = scene.shadows.lock().unwrap_or_else(|e| e.into_inner());
        if shadows.drawn == wanted {
            return Ok(());
        }
        let max_size = gpu.limits.max_texture_dimension_2d;
        let bytes: u64 = maps.iter().map(|m| 4 * m.size as u64 * m.size as u64).sum();
        if size > max_size || bytes > gpu.max_binding() {
            return Err(Error::setting(
                "shading.shadow_map_size",
                format!(
                    "{} shadow maps of up to {size}×{size} texels ({} MiB) do not fit this GPU (images up to {max_size}, bindings up to {} MiB)",
                    maps.len(),
                    bytes >> 20,
                    gpu.max_binding() >> 20
                ),
            ));
        }
        gpu.scoped("drawing the shadow maps", || {
            make_room(gpu, &mut shadows, maps, bytes);
            gpu.queue.write_buffer(&shadows.maps, 0, bytemuck::cast_slice(maps));
            let stage = &self.stage;
            let pipeline = self.pipeline(gpu, scene.discards);
            // The table's last two bindings are the maps being drawn: stand-ins there.
            let [a, b, c, d, e, f, ..] = scene.group1(&shadows);
            let empty = gpu.init_buffer("no shadow maps", &[0; 80], wgpu::BufferUsages::STORAGE);
            let materials = stage.bind_group(gpu, None, 1, &[&a, &b, &c, &d, &e, &f, &empty, &empty]);
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            for ((clip_from_scene, _), map) in wanted.iter().zip(maps) {
                let texture = shadows.textures.iter().find(|t| t.width() == map.size).expect("just made");
                let depth_view = texture.create_view(&Default::default());
                let params = gpu.init_buffer(
                    "shadow params",
                    bytemuck::bytes_of(&ShadowParams { clip_from_scene: *clip_from_scene }),
                    wgpu::BufferUsages::UNIFORM,
                );
                let group0 = stage.bind_group(gpu, None, 0, &[&params]);
                {
                    let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                        label: Some("shadow map"),
                        color_attachments: &[],
                        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                            view: &depth_view,
                            depth_ops: Some(wgpu::Operations {
                                load: wgpu::LoadOp::Clear(1.0),
                                store: wgpu::StoreOp::Store,
                            }),
                            stencil_ops: None,
                        }),
                        timestamp_writes: None,
                        occlusion_query_set: None,
                        multiview_mask: None,
                    });
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(0, &group0, &[]);
                    pass.set_bind_group(1, &materials, &[]);
                    pass.set_vertex_buffer(0, scene.vertices.slice(..));
                    pass.set_index_buffer(scene.indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..3 * scene.triangle_count, 0, 0..1);
                }
                copy_depths(&mut enc, texture, &shadows.depths, map);
            }
            gpu.queue.submit([enc.finish()]);
            Ok(())
        })?;
        shadows.drawn = wanted;
        Ok(())
    }
}

/// Room for `maps`: the depth buffer grown to `bytes`, a depth texture per map size (a depth
/// texture is copied whole: the maps', and a cube's faces'), those of other sizes dropped.
fn make_room(gpu: &Gpu, shadows: &mut GpuShadows, maps: &[GpuShadowMap], bytes: u64) {
    if shadows.depths.size() < bytes {
        shadows.depths = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shadow depths"),
            size: bytes,
            // COPY_SRC: the twin test reads the depths back.
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
    }
    shadows.textures.retain(|t| maps.iter().any(|m| m.size == t.width()));
    for map in maps {
        if !shadows.textures.iter().any(|t| t.width() == map.size) {
            shadows.textures.push(gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("shadow map"),
                size: wgpu::Extent3d { width: map.size, height: map.size, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: DEPTH_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            }));
        }
    }
}

/// Copies a drawn map's depth texture into its place in the depth buffer.
fn copy_depths(enc: &mut wgpu::CommandEncoder, texture: &wgpu::Texture, depths: &wgpu::Buffer, map: &GpuShadowMap) {
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::DepthOnly,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: depths,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 4 * map.offset as u64,
                bytes_per_row: Some(4 * map.size),
                rows_per_image: Some(map.size),
            },
        },
        wgpu::Extent3d { width: map.size, height: map.size, depth_or_array_layers: 1 },
    );
}
