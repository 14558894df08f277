//! The render targets (colour, display-position error, object id, distance, depth), made once
//! per image size and reused across frames: each a 2-layer texture, layer 0 the left eye and
//! layer 1 the right; the render pass that draws one eye into its layer, or both eyes at once
//! (multiview); and their read-back.

use crate::core::frame::EyeImage;
use crate::core::panoramas::projection::Eye;
use crate::core::settings::RenderSettings;
use crate::core::shading::color::srgb_to_linear;
use crate::error::Result;
use crate::gpu::device::{error_target_format, Gpu};
use crate::shader::{ErrorTarget, EyesPerDraw};

/// The colour target holds display (sRGB-encoded) values; the fragment stage writes linear light
/// and the target encodes it (cheaper than encoding in the shader on lavapipe).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
pub const OBJECT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The surface point each pixel shows (viewer frame) in xyz, w = 1 (0: background).
pub const POSITION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// The linear colour's target of an HDR frame (`--hdr`): floats.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// The location of the linear colour's target (after the colour and the measuring targets).
pub const HDR_LOCATION: usize = 5;

/// Which layers a render pass draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Layers {
    /// One eye (0 left, 1 right).
    Eye(usize),
    /// Both eyes, as the two views of a multiview pass.
    Both,
}

impl Layers {
    /// The raster stage's passes: one multiview pass drawing both eyes, or one per eye.
    pub fn passes(eyes: EyesPerDraw) -> &'static [Layers] {
        match eyes {
            EyesPerDraw::Both => &[Layers::Both],
            EyesPerDraw::One => &[Layers::Eye(0), Layers::Eye(1)],
        }
    }
}

/// What a render pass draws into: the frame's targets, one sample at each pixel's centre (every
/// output the frame asks for), or the multisampled colour (`--samples` N > 1: colour only, a
/// pass per eye, resolved into that eye's layer of the colour target).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Samples {
    Centre,
    Multi(u32),
}

impl Samples {
    /// The kinds of pass a frame with `settings` draws, in order: the centre pass alone (one
    /// sample), the multisampled colour alone, or both where the frame also wants outputs that
    /// must not be averaged (the error pass's targets, depth, positions, the linear colour).
    pub fn passes(settings: &RenderSettings) -> Vec<Samples> {
        let n = settings.shading.samples;
        let centre_outputs = settings.measure.outputs() > 1 || settings.shading.hdr;
        match (n > 1, centre_outputs) {
            (false, _) => vec![Samples::Centre],
            (true, false) => vec![Samples::Multi(n)],
            (true, true) => vec![Samples::Centre, Samples::Multi(n)],
        }
    }

    /// The layers each pass of this kind draws: multisampled passes draw one eye each.
    pub fn layers(self, eyes: EyesPerDraw) -> &'static [Layers] {
        match self {
            Samples::Centre => Layers::passes(eyes),
            Samples::Multi(_) => Layers::passes(EyesPerDraw::One),
        }
    }
}

/// A colour and a depth target of N samples (single-layer: wgpu has no multisampled array
/// textures), which the eyes' passes take in turn (one eye's samples are resolved at the end of
/// its pass, so the next pass may clear them: half the memory of a pair), or one pair per eye
/// (`per_eye`: a frame drawn in chunks, whose later passes load what the eye's earlier ones
/// drew); each pass resolved into a single-layer target of its eye's and copied into its layer of
/// the frame's colour target ([`Targets::copy_resolved`]; lavapipe resolved a pass into a layer
/// view of the 2-layer target always into layer 0).
pub struct Multisampled {
    pub samples: u32,
    color: Vec<wgpu::Texture>,
    depth: Vec<wgpu::Texture>,
    resolved: [wgpu::Texture; 2],
}

impl Multisampled {
    /// Whether each eye has its own samples.
    pub fn per_eye(&self) -> bool {
        self.color.len() == 2
    }
}

pub struct Targets {
    pub width: u32,
    pub height: u32,
    pub color: wgpu::Texture,
    pub error: wgpu::Texture,
    pub object: wgpu::Texture,
    /// Distance from each pixel's eye point (the error target's format).
    pub distance: wgpu::Texture,
    /// The surface points (`POSITION_FORMAT`), made only when asked for (16 bytes a pixel).
    pub position: Option<wgpu::Texture>,
    pub depth: wgpu::Texture,
    /// The linear colour × 2^EV in floats (`HDR_FORMAT`, at `HDR_LOCATION`), made only for
    /// `--hdr`; drawn beside `color` in the same passes.
    pub hdr_color: Option<wgpu::Texture>,
    /// Whether `hdr_color` is there.
    pub hdr: bool,
    /// The multisampled colour (`--samples` N > 1).
    pub multisampled: Option<Multisampled>,
    error_target: ErrorTarget,
    /// The mappable buffer the narrow targets (at most 4 bytes a texel: colour, distance,
    /// object, error) are read back through, kept from frame to frame: a fresh one each frame cost
    /// lavapipe 64 MB of new pages at 4096×2048 (the wider targets, read only when measuring,
    /// take a buffer of their own).
    readback: std::sync::Mutex<Option<wgpu::Buffer>>,
}

impl Targets {
    pub fn new(gpu: &Gpu, width: u32, height: u32, positions: bool, hdr: bool, samples: u32) -> Targets {
        let texture = |format, usage, label: &str, layers, sample_count| {
            gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: layers },
                mip_level_count: 1,
                sample_count,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let make = |format, usage, label: &str| texture(format, usage, label, 2, 1);
        // COPY_DST: the ray tracer copies its outputs in.
        let copyable =
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST;
        let depth = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let error_format = error_target_format(gpu.error_target);
        Targets {
            width,
            height,
            color: make(COLOR_FORMAT, copyable, "colour"),
            hdr_color: hdr.then(|| make(HDR_FORMAT, copyable, "linear colour")),
            error: make(error_format, copyable, "error"),
            object: make(OBJECT_FORMAT, copyable, "object"),
            distance: make(error_format, copyable, "distance"),
            position: positions.then(|| make(POSITION_FORMAT, copyable, "position")),
            depth: make(DEPTH_FORMAT, depth, "depth"),
            hdr,
            multisampled: (samples > 1).then(|| Multisampled {
                samples,
                color: vec![texture(COLOR_FORMAT, depth, "colour samples", 1, samples)],
                depth: vec![texture(DEPTH_FORMAT, depth, "depth samples", 1, samples)],
                resolved: ["left", "right"].map(|e| {
                    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
                    texture(COLOR_FORMAT, usage, &format!("{e} colour resolved"), 1, 1)
                }),
            }),
            error_target: gpu.error_target,
            readback: Default::default(),
        }
    }

    /// Gives the right eye multisampled targets of its own (the left keeps the ones the eyes
    /// shared), for a frame drawn in chunks: its later passes load what each eye's earlier ones
    /// drew.
    pub fn give_each_eye_its_samples(&mut self, gpu: &Gpu) {
        let (width, height) = (self.width, self.height);
        let Some(ms) = self.multisampled.as_mut().filter(|m| !m.per_eye()) else { return };
        let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
        let texture = |format, label: &str| {
            gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: ms.samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
        };
        let (color, depth) =
            (texture(COLOR_FORMAT, "right colour samples"), texture(DEPTH_FORMAT, "right depth samples"));
        ms.color.push(color);
        ms.depth.push(depth);
    }

    /// Begins a render pass drawing `layers`, clearing their targets first if `clear`
    /// (background colour, error −1, object 0, distance +∞, depth 1); the error, object and
    /// distance targets only when measuring (`MeasureSettings::targets`), and the positions
    /// target when it is measured too.
    pub fn begin_pass<'e>(
        &self,
        enc: &'e mut wgpu::CommandEncoder,
        layers: Layers,
        settings: &RenderSettings,
        clear: bool,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'e>>,
    ) -> wgpu::RenderPass<'e> {
        let outputs = settings.measure.outputs();
        let (dimension, base_array_layer, array_layer_count, multiview_mask) = match layers {
            Layers::Eye(k) => (wgpu::TextureViewDimension::D2, k as u32, 1, None),
            Layers::Both => (wgpu::TextureViewDimension::D2Array, 0, 2, std::num::NonZeroU32::new(0b11)),
        };
        let view = |t: &wgpu::Texture| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(dimension),
                base_array_layer,
                array_layer_count: Some(array_layer_count),
                ..Default::default()
            })
        };
        let position = (outputs > 4)
            .then(|| self.position.as_ref().expect("the targets were made with positions where they are measured"));
        let all = [&self.color, &self.error, &self.object, &self.distance];
        let views: Vec<wgpu::TextureView> = all.into_iter().chain(position).take(outputs).map(view).collect();
        let depth_view = view(&self.depth);
        let value = |x: f32| match self.error_target {
            ErrorTarget::Float => x as f64,
            ErrorTarget::UintBits => x.to_bits() as f64,
        };
        let clears = [
            background_clear(settings),
            wgpu::Color { r: value(-1.0), ..wgpu::Color::TRANSPARENT },
            wgpu::Color::TRANSPARENT,
            wgpu::Color { r: value(f32::INFINITY), ..wgpu::Color::TRANSPARENT },
            wgpu::Color::TRANSPARENT,
        ];
        let hdr_view = self.hdr_color.as_ref().map(view);
        let attach = |view, c| attachment(view, None, c, clear);
        let mut attachments: Vec<Option<wgpu::RenderPassColorAttachment>> =
            views.iter().zip(clears).map(|(view, c)| attach(view, c)).collect();
        if let Some(hdr) = &hdr_view {
            // The linear colour, cleared to the background's (linear) colour.
            attachments.resize(HDR_LOCATION, None);
            attachments.push(attach(hdr, clears[0]));
        }
        let label = match layers {
            Layers::Eye(k) => Eye::BOTH[k].name(),
            Layers::Both => "both eyes",
        };
        begin(enc, label, &attachments, &depth_view, clear, timestamp_writes, multiview_mask)
    }

    /// Begins a render pass of `samples` (see [`Samples`]) drawing `layers`: the frame's targets
    /// ([`Targets::begin_pass`]) or one eye's multisampled colour, resolved at the pass's end
    /// into the eye's resolve target ([`Targets::copy_resolved`] copies it into the colour's
    /// layer).
    pub fn begin_samples_pass<'e>(
        &self,
        enc: &'e mut wgpu::CommandEncoder,
        samples: Samples,
        layers: Layers,
        settings: &RenderSettings,
        clear: bool,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'e>>,
    ) -> wgpu::RenderPass<'e> {
        let (Samples::Multi(_), Layers::Eye(k)) = (samples, layers) else {
            return self.begin_pass(enc, layers, settings, clear, timestamp_writes);
        };
        let ms = self.multisampled.as_ref().expect("the targets were made with the frame's samples");
        let resolve = ms.resolved[k].create_view(&Default::default());
        let color = ms.color[k % ms.color.len()].create_view(&Default::default());
        let depth = ms.depth[k % ms.depth.len()].create_view(&Default::default());
        let attachments = [attachment(&color, Some(&resolve), background_clear(settings), clear)];
        let label = if k == 0 { "left eye's samples" } else { "right eye's samples" };
        begin(enc, label, &attachments, &depth, clear, timestamp_writes, None)
    }

    /// After the multisampled colour's passes (if any were made): copies each eye's resolved
    /// colour into its layer of the colour target.
    pub fn copy_resolved(&self, enc: &mut wgpu::CommandEncoder) {
        let Some(ms) = &self.multisampled else { return };
        for (k, resolved) in ms.resolved.iter().enumerate() {
            enc.copy_texture_to_texture(
                resolved.as_image_copy(),
                wgpu::TexelCopyTextureInfo {
                    texture: &self.color,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y: 0, z: k as u32 },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::Extent3d { width: self.width, height: self.height, depth_or_array_layers: 1 },
            );
        }
    }

    /// Reads both eyes' colour targets back.
    pub fn read_colors(&self, gpu: &Gpu) -> Result<[EyeImage; 2]> {
        let (width, height) = (self.width, self.height);
        Ok(self.read_eyes::<u8>(gpu, &self.color)?.map(|rgba| EyeImage { width, height, rgba }))
    }

    /// Reads both eyes' linear colours back from an HDR colour target (RGB).
    pub fn read_hdr(&self, gpu: &Gpu) -> Result<[Vec<[f32; 3]>; 2]> {
        let texture = self.hdr_color.as_ref().expect("made for the linear colour (shading.hdr)");
        Ok(self.read_eyes::<[f32; 4]>(gpu, texture)?.map(|v| v.into_iter().map(|p| [p[0], p[1], p[2]]).collect()))
    }

    /// Reads both eyes' distances back (metres; +∞ where no surface is drawn).
    pub fn read_distances(&self, gpu: &Gpu) -> Result<[Vec<f32>; 2]> {
        self.read_eyes::<f32>(gpu, &self.distance)
    }

    /// Reads both eyes' surface points back (NaN where no surface is drawn).
    pub fn read_positions(&self, gpu: &Gpu) -> Result<[Vec<[f32; 3]>; 2]> {
        let texture = self.position.as_ref().expect("made with positions");
        Ok(self
            .read_eyes::<[f32; 4]>(gpu, texture)?
            .map(|v| v.into_iter().map(|p| if p[3] > 0.0 { [p[0], p[1], p[2]] } else { [f32::NAN; 3] }).collect()))
    }

    /// Reads both eyes' display-position errors back (the error target's words as f32 bits:
    /// see [`crate::shader::ErrorTarget`]).
    pub fn read_errors(&self, gpu: &Gpu) -> Result<[Vec<f32>; 2]> {
        self.read_eyes::<f32>(gpu, &self.error)
    }

    /// Reads both eyes' object ids back.
    pub fn read_objects(&self, gpu: &Gpu) -> Result<[Vec<u32>; 2]> {
        self.read_eyes::<u32>(gpu, &self.object)
    }

    /// Both eyes' texels of one of the targets read back, each eye's rows unpadded, as `T`s (a
    /// texel's bytes a whole number of them): one copy into a mappable buffer (kept for the
    /// narrow targets, see `readback`), then one pass from its mapping into each eye's own
    /// vector, allocated once at its size.
    fn read_eyes<T: bytemuck::Pod>(&self, gpu: &Gpu, texture: &wgpu::Texture) -> Result<[Vec<T>; 2]> {
        let h = texture.height() as usize;
        let texel = texture.format().block_copy_size(None).expect("a colour format");
        let row = texel as usize * texture.width() as usize / std::mem::size_of::<T>();
        let (size, padded) = eyes_buffer_size(texture);
        let mut kept = self.readback.lock().unwrap_or_else(|e| e.into_inner());
        let fresh;
        let buffer = if texel <= 4 {
            if kept.as_ref().is_none_or(|b| b.size() < size) {
                *kept = Some(readback_buffer(gpu, size));
            }
            kept.as_ref().expect("made")
        } else {
            fresh = readback_buffer(gpu, size);
            &fresh
        };
        copy_eyes_into(gpu, texture, buffer, padded);
        let stride = padded as usize / std::mem::size_of::<T>();
        gpu.read_mapped(buffer, |bytes| unpad(bytemuck::cast_slice(&bytes[..size as usize]), row, h, stride))
    }
}

/// The samples per pixel the adapter draws the colour and depth targets with: 1 and 4 always
/// (WebGPU's guarantee), others where the adapter's format features (asked for with
/// `TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES`) list them for both.
pub fn sample_counts(gpu: &Gpu) -> Vec<u32> {
    let adapter = &gpu.adapter;
    let specific = gpu.features.contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES);
    let supports = |n: u32| {
        [COLOR_FORMAT, DEPTH_FORMAT]
            .iter()
            .all(|&f| adapter.get_texture_format_features(f).flags.sample_count_supported(n))
    };
    crate::core::settings::SAMPLE_COUNTS
        .into_iter()
        .filter(|&n| n == 1 || n == 4 || (specific && supports(n)))
        .collect()
}

/// The background's clear colour: given as display values, the sRGB target takes linear ones.
fn background_clear(settings: &RenderSettings) -> wgpu::Color {
    let [r, g, b] = settings.shading.background.map(|c| srgb_to_linear(c) as f64);
    wgpu::Color { r, g, b, a: 1.0 }
}

/// A colour attachment, cleared to `c` first if `clear`, resolved into `resolve` if given.
fn attachment<'a>(
    view: &'a wgpu::TextureView,
    resolve: Option<&'a wgpu::TextureView>,
    c: wgpu::Color,
    clear: bool,
) -> Option<wgpu::RenderPassColorAttachment<'a>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: resolve,
        ops: wgpu::Operations {
            load: if clear { wgpu::LoadOp::Clear(c) } else { wgpu::LoadOp::Load },
            store: wgpu::StoreOp::Store,
        },
    })
}

/// Begins a render pass into `attachments` and `depth` (cleared to 1 first if `clear`).
fn begin<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    attachments: &[Option<wgpu::RenderPassColorAttachment>],
    depth: &wgpu::TextureView,
    clear: bool,
    timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'e>>,
    multiview_mask: Option<std::num::NonZeroU32>,
) -> wgpu::RenderPass<'e> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: attachments,
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations {
                load: if clear { wgpu::LoadOp::Clear(1.0) } else { wgpu::LoadOp::Load },
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes,
        occlusion_query_set: None,
        multiview_mask,
    })
}

/// Copies both layers (eyes) of a target into one buffer (rows padded to 256 bytes, eyes one
/// after the other). Returns the buffer and the padded row length in 4-byte words.
pub fn copy_eyes_to_buffer(gpu: &Gpu, texture: &wgpu::Texture, usage: wgpu::BufferUsages) -> (wgpu::Buffer, u32) {
    let (size, padded) = eyes_buffer_size(texture);
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("eye texels"),
        size,
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    copy_eyes_into(gpu, texture, &buffer, padded);
    (buffer, padded / 4)
}

/// The bytes both eyes of a two-layer texture take in a buffer, and a row's (padded to
/// `COPY_BYTES_PER_ROW_ALIGNMENT`).
fn eyes_buffer_size(texture: &wgpu::Texture) -> (u64, u32) {
    let texel = texture.format().block_copy_size(None).expect("a colour format");
    let padded =
        (texel * texture.width()).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    (2 * padded as u64 * texture.height() as u64, padded)
}

/// A buffer of `size` bytes that a copy fills and the CPU maps.
fn readback_buffer(gpu: &Gpu, size: u64) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("eye texels read back"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Copies both eyes (layers) of `texture` into `buffer`, eye k at k × the eye's bytes, rows of
/// `padded` bytes, and submits the copy.
fn copy_eyes_into(gpu: &Gpu, texture: &wgpu::Texture, buffer: &wgpu::Buffer, padded: u32) {
    let (w, h) = (texture.width(), texture.height());
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    for k in 0..2u32 {
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: 0, z: k },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: k as u64 * (padded as u64 * h as u64),
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
    }
    gpu.queue.submit([enc.finish()]);
}

/// Unpads the texels of both eyes from a buffer made by [`copy_eyes_to_buffer`] and downloaded
/// (`w`: words per row; the targets' own read-backs unpad from the mapping: `Targets::read_eyes`).
pub fn unpad_eyes(data: &[u8], w: u32, h: u32, stride: u32) -> [Vec<u32>; 2] {
    unpad(bytemuck::cast_slice(data), w as usize, h as usize, stride as usize)
}

/// Both eyes' `row` values of each of `h` rows from `data` (eye after eye, rows `stride` values
/// apart), each eye's vector allocated once at its size.
fn unpad<T: bytemuck::Pod>(data: &[T], row: usize, h: usize, stride: usize) -> [Vec<T>; 2] {
    std::array::from_fn(|k| {
        let eye = &data[k * stride * h..][..stride * h];
        let mut out = Vec::with_capacity(row * h);
        for y in 0..h {
            out.extend_from_slice(&eye[y * stride..][..row]);
        }
        out
    })
}
