//! The headless renderer: the `prepare` compute pre-pass, then the `raster` stage draws the
//! prepared triangles indirectly for each eye into RGBA8 + depth, and the images are read back.
//!
//! The prepared-triangle buffer has a capacity; the pre-pass counts what it wanted to write and
//! never writes past the end. When a chunk of the scene overflows, the buffer grows (up to the
//! device's storage-binding limit or the caller's budget) and the chunk runs again; past the
//! limit the chunk is halved. Chunks draw one after another into the same targets, so nothing is
//! dropped and the number of chunks is reported.

use std::time::Instant;

use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

use crate::gpu::Gpu;
use crate::gpu_types::{DrawIndirectArgs, DrawVertex, PrepareParams, RasterParams};
use crate::prepare::{prepare_params, MAX_OUT_PER_TRIANGLE};
use crate::projection::{Eye, Projection};
use crate::scene::Scene;
use crate::shaders;

pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const DRAW_VERTEX_SIZE: u64 = std::mem::size_of::<DrawVertex>() as u64;

/// Where the viewer stands and how the images are made.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub projection: Projection,
    /// Viewer position in scene coordinates.
    pub viewer: Vec3,
    /// Turn of the view about +y in degrees; positive turns left (counter-clockwise from above).
    pub yaw_deg: f32,
    /// Background colour, each channel in [0, 1].
    pub background: [f32; 3],
    /// Ambient term of the headlight shading.
    pub ambient: f32,
    /// Most prepared triangles held at once (None: as many as the device can bind).
    pub max_prepared_triangles: Option<u32>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            projection: Projection::default(),
            viewer: Vec3::ZERO,
            yaw_deg: 0.0,
            background: [0.1, 0.1, 0.12],
            ambient: 0.3,
            max_prepared_triangles: None,
        }
    }
}

impl RenderSettings {
    /// World → viewer frame: translate the viewer to the origin, then undo the yaw.
    pub fn view(&self) -> Mat4 {
        Mat4::from_rotation_y(-self.yaw_deg.to_radians()) * Mat4::from_translation(-self.viewer)
    }

    pub fn raster_params(&self, eye: Eye) -> RasterParams {
        RasterParams {
            projection: (&self.projection).into(),
            eye_sign: eye.sign(),
            ambient: self.ambient,
            _pad: [0.0; 2],
        }
    }
}

/// One eye's image, tightly packed RGBA8 rows, top row first.
#[derive(Clone, Debug)]
pub struct EyeImage {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

impl EyeImage {
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 4] {
        let i = 4 * (y * self.width + x) as usize;
        [
            self.rgba[i],
            self.rgba[i + 1],
            self.rgba[i + 2],
            self.rgba[i + 3],
        ]
    }
}

/// What a render cost and drew. Times are wall-clock milliseconds around submit-and-wait.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct FrameStats {
    pub triangles_in: u64,
    pub triangles_drawn: u64,
    pub chunks: u32,
    pub ms_prepare: f64,
    pub ms_raster: f64,
    pub ms_readback: f64,
    pub ms_total: f64,
}

pub struct Frame {
    pub left: EyeImage,
    pub right: EyeImage,
    pub stats: FrameStats,
}

impl Frame {
    pub fn eye(&self, eye: Eye) -> &EyeImage {
        match eye {
            Eye::Left => &self.left,
            Eye::Right => &self.right,
        }
    }
}

/// A scene uploaded to the GPU.
pub struct GpuScene {
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub triangle_count: u32,
}

impl GpuScene {
    /// Validates and uploads a scene; fails with a clear message if it cannot fit the device.
    pub fn upload(gpu: &Gpu, scene: &Scene) -> Result<GpuScene, String> {
        scene.validate()?;
        let vbytes = std::mem::size_of_val(scene.vertices.as_slice()) as u64;
        let ibytes = std::mem::size_of_val(scene.indices.as_slice()) as u64;
        let max = gpu
            .limits
            .max_storage_buffer_binding_size
            .min(gpu.limits.max_buffer_size);
        if vbytes > max || ibytes > max {
            return Err(format!(
                "scene too big for this GPU: {} vertices ({} MiB) and {} triangles ({} MiB); one buffer may hold at most {} MiB",
                scene.vertices.len(),
                vbytes >> 20,
                scene.triangle_count(),
                ibytes >> 20,
                max >> 20
            ));
        }
        let pad = |b: &[u8]| {
            if b.is_empty() {
                vec![0u8; 16]
            } else {
                b.to_vec()
            }
        };
        let vertices = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene vertices"),
                contents: &pad(bytemuck::cast_slice(&scene.vertices)),
                usage: wgpu::BufferUsages::STORAGE,
            });
        let indices = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene indices"),
                contents: &pad(bytemuck::cast_slice(&scene.indices)),
                usage: wgpu::BufferUsages::STORAGE,
            });
        Ok(GpuScene {
            vertices,
            indices,
            triangle_count: scene.triangle_count() as u32,
        })
    }
}

/// The output of one `prepare` dispatch.
pub struct Prepared {
    pub vertices: wgpu::Buffer,
    pub draw_args: wgpu::Buffer,
    /// Triangles the stage wanted to write; more than `capacity` means it overflowed.
    pub requested: u32,
    pub capacity: u32,
}

pub struct Renderer {
    pub gpu: Gpu,
    prepare: wgpu::ComputePipeline,
    finalize: wgpu::ComputePipeline,
    raster: wgpu::RenderPipeline,
}

struct Targets {
    color: [wgpu::Texture; 2],
    depth: [wgpu::Texture; 2],
}

impl Renderer {
    pub fn new(gpu: Gpu) -> Renderer {
        let device = &gpu.device;
        let prepare_module = shaders::load(device, &shaders::PREPARE);
        let compute = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: None,
                module: &prepare_module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let prepare = compute("prepare");
        let finalize = compute("finalize");
        let raster_module = shaders::load(device, &shaders::RASTER);
        let attributes = wgpu::vertex_attr_array![
            0 => Float32x3, 1 => Float32, 2 => Float32x3, 3 => Uint32, 4 => Float32x4, 5 => Float32x2
        ];
        let raster = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("raster"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &raster_module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: DRAW_VERTEX_SIZE,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &attributes,
                })],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                cull_mode: None,
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
            fragment: Some(wgpu::FragmentState {
                module: &raster_module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: COLOR_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        Renderer {
            gpu,
            prepare,
            finalize,
            raster,
        }
    }

    /// The most prepared triangles one buffer can hold on this device.
    pub fn max_capacity(&self) -> u32 {
        let limit = self
            .gpu
            .limits
            .max_storage_buffer_binding_size
            .min(self.gpu.limits.max_buffer_size);
        (limit / (3 * DRAW_VERTEX_SIZE)).min(u32::MAX as u64) as u32
    }

    fn prepared_buffer(&self, capacity: u32) -> wgpu::Buffer {
        self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("prepared triangles"),
            size: (capacity.max(1) as u64) * 3 * DRAW_VERTEX_SIZE,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::VERTEX
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        })
    }

    /// Runs `prepare` + `finalize` on one range of triangles into `out` (capacity in triangles).
    fn run_prepare(&self, scene: &GpuScene, params: &PrepareParams, out: wgpu::Buffer) -> Prepared {
        let device = &self.gpu.device;
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("prepare params"),
            contents: bytemuck::bytes_of(params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let counter = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("prepare counter"),
            contents: &[0u8; 4],
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        });
        let draw_args = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("draw args"),
            size: std::mem::size_of::<DrawIndirectArgs>() as u64,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::INDIRECT
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bind = |pipeline: &wgpu::ComputePipeline, entries: &[(u32, &wgpu::Buffer)]| {
            let entries: Vec<wgpu::BindGroupEntry> = entries
                .iter()
                .map(|(b, buf)| wgpu::BindGroupEntry {
                    binding: *b,
                    resource: buf.as_entire_binding(),
                })
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            })
        };
        let prepare_bg = bind(
            &self.prepare,
            &[
                (0, &uniform),
                (1, &scene.vertices),
                (2, &scene.indices),
                (3, &out),
                (4, &counter),
            ],
        );
        let finalize_bg = bind(
            &self.finalize,
            &[(0, &uniform), (4, &counter), (5, &draw_args)],
        );
        let mut enc = device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.prepare);
            pass.set_bind_group(0, &prepare_bg, &[]);
            let groups = params.triangle_count.div_ceil(64).max(1);
            let (x, y) = if groups <= 65535 {
                (groups, 1)
            } else {
                (65535, groups.div_ceil(65535))
            };
            pass.dispatch_workgroups(x, y, 1);
            pass.set_pipeline(&self.finalize);
            pass.set_bind_group(0, &finalize_bg, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        self.gpu.queue.submit([enc.finish()]);
        let requested = u32::from_le_bytes(self.gpu.download(&counter, 4)[..4].try_into().unwrap());
        Prepared {
            vertices: out,
            draw_args,
            requested,
            capacity: params.capacity,
        }
    }

    /// Runs the pre-pass alone on the whole scene (growing the buffer as needed) and reads the
    /// prepared triangles back: the GPU side of the CPU-twin tests.
    pub fn prepare_readback(&self, scene: &GpuScene, settings: &RenderSettings) -> Vec<DrawVertex> {
        let mut capacity = scene.triangle_count.saturating_mul(2).max(64);
        loop {
            let params = prepare_params(
                &settings.projection,
                settings.view(),
                scene.triangle_count,
                0,
                capacity,
            );
            let p = self.run_prepare(scene, &params, self.prepared_buffer(capacity));
            if p.requested <= capacity {
                let bytes = self
                    .gpu
                    .download(&p.vertices, p.requested as u64 * 3 * DRAW_VERTEX_SIZE);
                return bytemuck::cast_slice(&bytes).to_vec();
            }
            capacity = p.requested;
        }
    }

    fn targets(&self, projection: &Projection) -> Targets {
        let make = |format, usage, label| {
            self.gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: projection.width,
                    height: projection.height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let color_usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let depth_usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        Targets {
            color: [
                make(COLOR_FORMAT, color_usage, "left colour"),
                make(COLOR_FORMAT, color_usage, "right colour"),
            ],
            depth: [
                make(DEPTH_FORMAT, depth_usage, "left depth"),
                make(DEPTH_FORMAT, depth_usage, "right depth"),
            ],
        }
    }

    /// Draws prepared triangles into both eyes' targets (clearing them first if `clear`).
    fn raster_eyes(
        &self,
        targets: &Targets,
        prepared: &Prepared,
        settings: &RenderSettings,
        clear: bool,
    ) {
        let device = &self.gpu.device;
        let mut enc = device.create_command_encoder(&Default::default());
        for (k, eye) in Eye::BOTH.into_iter().enumerate() {
            let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("raster params"),
                contents: bytemuck::bytes_of(&settings.raster_params(eye)),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &self.raster.get_bind_group_layout(0),
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                }],
            });
            let color_view = targets.color[k].create_view(&Default::default());
            let depth_view = targets.depth[k].create_view(&Default::default());
            let [r, g, b] = settings.background;
            let color_load = if clear {
                wgpu::LoadOp::Clear(wgpu::Color {
                    r: r as f64,
                    g: g as f64,
                    b: b as f64,
                    a: 1.0,
                })
            } else {
                wgpu::LoadOp::Load
            };
            let depth_load = if clear {
                wgpu::LoadOp::Clear(1.0)
            } else {
                wgpu::LoadOp::Load
            };
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(eye.name()),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &color_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: color_load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: depth_load,
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.raster);
            pass.set_bind_group(0, &bg, &[]);
            pass.set_vertex_buffer(0, prepared.vertices.slice(..));
            pass.draw_indirect(&prepared.draw_args, 0);
        }
        self.gpu.queue.submit([enc.finish()]);
        self.gpu.wait();
    }

    fn read_color(&self, texture: &wgpu::Texture) -> EyeImage {
        let (w, h) = (texture.width(), texture.height());
        let row = 4 * w;
        let padded =
            row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let staging = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("colour readback"),
            size: (padded * h) as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        self.gpu.queue.submit([enc.finish()]);
        let data = self.gpu.read_buffer(&staging);
        let mut rgba = Vec::with_capacity((row * h) as usize);
        for y in 0..h as usize {
            rgba.extend_from_slice(&data[y * padded as usize..y * padded as usize + row as usize]);
        }
        EyeImage {
            width: w,
            height: h,
            rgba,
        }
    }

    /// Renders both eyes of an uploaded scene.
    pub fn render(&self, scene: &GpuScene, settings: &RenderSettings) -> Result<Frame, String> {
        settings.projection.validate()?;
        let start = Instant::now();
        let mut stats = FrameStats {
            triangles_in: scene.triangle_count as u64,
            ..Default::default()
        };
        let targets = self.targets(&settings.projection);
        let max_capacity = settings
            .max_prepared_triangles
            .unwrap_or(u32::MAX)
            .min(self.max_capacity())
            .max(MAX_OUT_PER_TRIANGLE);
        let n = scene.triangle_count;
        let mut capacity = n.saturating_mul(2).saturating_add(1024).min(max_capacity);
        let mut out = self.prepared_buffer(capacity);
        let (mut first, mut chunk) = (0u32, n.max(1));
        let mut cleared = false;
        while first < n || !cleared {
            let count = chunk.min(n - first);
            let params = prepare_params(
                &settings.projection,
                settings.view(),
                count,
                first,
                capacity,
            );
            let t = Instant::now();
            let prepared = self.run_prepare(scene, &params, out);
            stats.ms_prepare += t.elapsed().as_secs_f64() * 1e3;
            if prepared.requested > capacity {
                out = prepared.vertices;
                if prepared.requested <= max_capacity {
                    capacity = prepared.requested;
                    out = self.prepared_buffer(capacity);
                } else {
                    // Cannot hold this chunk's output at once: halve the chunk. A single triangle
                    // makes at most MAX_OUT_PER_TRIANGLE ≤ max_capacity, so this ends.
                    chunk = (count / 2).max(1);
                }
                continue;
            }
            let t = Instant::now();
            self.raster_eyes(&targets, &prepared, settings, !cleared);
            stats.ms_raster += t.elapsed().as_secs_f64() * 1e3;
            cleared = true;
            stats.triangles_drawn += prepared.requested as u64;
            stats.chunks += 1;
            first += count;
            out = prepared.vertices;
        }
        let t = Instant::now();
        let left = self.read_color(&targets.color[0]);
        let right = self.read_color(&targets.color[1]);
        stats.ms_readback = t.elapsed().as_secs_f64() * 1e3;
        stats.ms_total = start.elapsed().as_secs_f64() * 1e3;
        Ok(Frame { left, right, stats })
    }
}

impl Renderer {
    /// Runs the `project_points` stage: pixel positions of viewer-frame points for one eye.
    pub fn project_points(
        &self,
        projection: &Projection,
        eye: Eye,
        points: &[Vec3],
    ) -> Vec<[f32; 4]> {
        #[repr(C)]
        #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
        struct ProjectParams {
            projection: crate::gpu_types::ProjectionUniform,
            eye_sign: f32,
            count: u32,
            _pad: [f32; 2],
        }
        let device = &self.gpu.device;
        let module = shaders::load(device, &shaders::PROJECT_POINTS);
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("project_points"),
            layout: None,
            module: &module,
            entry_point: Some("project_points"),
            compilation_options: Default::default(),
            cache: None,
        });
        let params = ProjectParams {
            projection: projection.into(),
            eye_sign: eye.sign(),
            count: points.len() as u32,
            _pad: [0.0; 2],
        };
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let input: Vec<[f32; 4]> = points.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect();
        let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::cast_slice(&input),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let size = (points.len() * 16) as u64;
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: input.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: output.as_entire_binding(),
                },
            ],
        });
        let mut enc = device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups((points.len() as u32).div_ceil(64), 1, 1);
        }
        self.gpu.queue.submit([enc.finish()]);
        bytemuck::cast_slice(&self.gpu.download(&output, size)).to_vec()
    }
}
