//! Image-based lighting (issue 17): an equirectangular radiance map — a Radiance `.hdr` or
//! OpenEXR file (`--environment`), or the built-in neutral studio — prepared for the glTF BRDF
//! by the split-sum approximation (Karis, "Real Shading in Unreal Engine 4", 2013):
//!
//! - **specular**: the radiance convolved with the GGX lobe for N = V = R, one equirectangular
//!   level per roughness 0, 1/5, …, 1 ([`ENV_LEVELS`]); level 0 is the radiance itself. Each
//!   texel sums [`PREFILTER_SAMPLES`] Hammersley directions importance-sampled from D, weighted
//!   by n·l, each read from the source's box-filtered mip level whose texel matches the sample's
//!   solid angle (filtered importance sampling, Křivánek & Colbert 2008), so a sun of a few
//!   texels spreads smoothly instead of speckling;
//! - **diffuse**: the irradiance E(n)/π as nine spherical-harmonic coefficients (Ramamoorthi &
//!   Hanrahan 2001: L_lm × Â_l/π with Â = π, 2π/3, π/4), exact for an environment of degree ≤ 2
//!   and within a few per cent of a cosine convolution otherwise (5 % on the neutral studio's dim side);
//! - **the BRDF table** ([`LUT_SIZE`]² texels over n·v and roughness): the scale A and bias B of
//!   f0 in the directional albedo of the specular lobe, ∫ f_spec n·l dω = f0·A + B, with the same
//!   separable Smith visibility as `brdf`.
//!
//! The fragment stage (`ibl_radiance` in surface.wgsl, twin in `cpu::fragment`) adds the
//! energy lost to single scattering back (Fdez-Agüera 2019): E_ss = f0·A + B, E_ms = 1 − (A + B),
//! F_avg = f0 + (1 − f0)/21, F_ms = E_ss·F_avg / (1 − E_ms·F_avg), diffuse weight
//! 1 − E_ss − F_ms·E_ms, so a white surface in a white environment reflects exactly what
//! arrives, rough or smooth, metal or not (the white-furnace test).
//!
//! Directions: longitude u = atan2(x, −z) across the image (the image's centre column looks along
//! −z, as the panorama's centre does), latitude asin(y) from the top row (+y) to the bottom.

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::error::{Error, Result};

/// Prefiltered levels: roughness k / (ENV_LEVELS − 1).
pub const ENV_LEVELS: usize = 6;
/// Side of the BRDF table (n·v × roughness).
pub const LUT_SIZE: usize = 32;
/// Samples per prefiltered texel and per BRDF table entry.
pub const PREFILTER_SAMPLES: u32 = 128;
pub const LUT_SAMPLES: u32 = 512;
/// Level 0 is the radiance at most this wide (a wider file is box-filtered down to it).
pub const MAX_ENV_WIDTH: u32 = 2048;
/// The largest environment file read, in texels (bounded memory for hostile headers).
const MAX_ENV_TEXELS: u64 = 64 << 20;

/// Linear radiance over the sphere, equirectangular, rows top (+y) to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub radiance: Vec<Vec3>,
}

/// The environment as the fragment stage reads it: the prefiltered levels (RGB9E5, one u32 per
/// texel: a shared 5-bit exponent and 9-bit mantissas, 0.2 % steps, up to 65,408) and the BRDF
/// table (A, B as two half floats) in one array, the levels' places, and the irradiance
/// coefficients. One 32-bit read per texel instead of four: lavapipe gathers each lane's read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PreparedEnvironment {
    pub name: String,
    pub texels: Vec<u32>,
    /// Per level: first texel, width, height.
    pub levels: [[u32; 3]; ENV_LEVELS],
    /// First texel of the BRDF table (A, B in x, y).
    pub lut_offset: u32,
    /// E(n)/π = Σ sh[i]·Y_i(n), clamped at 0.
    pub sh: [Vec3; 9],
    /// Whether background pixels show it (an environment the user gave does; the built-in
    /// neutral studio only lights).
    pub background: bool,
}

/// The unit direction at equirectangular image position (x, y) in texels (continuous).
pub fn direction_at(x: f32, y: f32, width: u32, height: u32) -> Vec3 {
    let u = (x / width as f32 - 0.5) * std::f32::consts::TAU;
    let lat = (0.5 - y / height as f32) * std::f32::consts::PI;
    Vec3::new(lat.cos() * u.sin(), lat.sin(), -lat.cos() * u.cos())
}

/// The continuous image position (texels) of unit direction d: the inverse of [`direction_at`].
pub fn position_of(d: Vec3, width: u32, height: u32) -> Vec2 {
    let u = d.x.atan2(-d.z);
    let lat = d.y.clamp(-1.0, 1.0).asin();
    Vec2::new((u / std::f32::consts::TAU + 0.5) * width as f32, (0.5 - lat / std::f32::consts::PI) * height as f32)
}

impl Environment {
    /// A uniform environment (the white furnace).
    pub fn uniform(radiance: Vec3) -> Environment {
        Environment { name: "uniform".into(), width: 64, height: 32, radiance: vec![radiance; 64 * 32] }
    }

    /// The built-in neutral studio: grey all round, brighter above than below (a soft sky and a
    /// darker floor, mean radiance about 0.8), with two broad soft-boxes high to the front-left
    /// and behind-right, so that metals show shape and highlights but take no colour.
    pub fn neutral() -> Environment {
        let (width, height) = (256u32, 128u32);
        let boxes = [(Vec3::new(-0.6, 0.6, -0.5).normalize(), 4.0f32), (Vec3::new(0.7, 0.4, 0.6).normalize(), 2.5)];
        let radiance = (0..width * height)
            .map(|i| {
                let d = direction_at((i % width) as f32 + 0.5, (i / width) as f32 + 0.5, width, height);
                let sky = 0.55 + 0.35 * d.y;
                let lights: f32 =
                    boxes.iter().map(|(c, l)| l * (((d.dot(*c) - 0.9) / 0.1).clamp(0.0, 1.0)).powi(2)).sum();
                Vec3::splat(sky + lights)
            })
            .collect();
        Environment { name: "neutral".into(), width, height, radiance }
    }

    /// Reads an equirectangular radiance map: Radiance RGBE (`.hdr`) or OpenEXR (`.exr`).
    pub fn load(path: &Path) -> Result<Environment> {
        let name = path.display().to_string();
        let bad = |m: String| Error::setting("environment", format!("{name}: {m}"));
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
        let (width, height, radiance) = match ext.as_str() {
            "hdr" => {
                let file = std::fs::File::open(path).map_err(|e| bad(e.to_string()))?;
                let decoder = image::codecs::hdr::HdrDecoder::new(std::io::BufReader::new(file))
                    .map_err(|e| bad(format!("not a Radiance HDR file ({e})")))?;
                let meta = decoder.metadata();
                check_size(meta.width, meta.height).map_err(bad)?;
                let image = image::DynamicImage::from_decoder(decoder).map_err(|e| bad(e.to_string()))?.into_rgb32f();
                let radiance = image.pixels().map(|p| Vec3::from(p.0)).collect();
                (image.width(), image.height(), radiance)
            }
            "exr" => {
                use exr::prelude::*;
                let image = read_first_rgba_layer_from_file(
                    path,
                    |resolution, _| {
                        let (w, h) = (resolution.width(), resolution.height());
                        let ok = (w as u64) * (h as u64) <= MAX_ENV_TEXELS;
                        (w, if ok { vec![Vec3::ZERO; w * h] } else { Vec::new() })
                    },
                    |(w, texels), position, (r, g, b, _a): (f32, f32, f32, f32)| {
                        if !texels.is_empty() {
                            texels[position.y() * *w + position.x()] = Vec3::new(r, g, b);
                        }
                    },
                )
                .map_err(|e| bad(format!("not a readable OpenEXR file ({e})")))?;
                let size = image.layer_data.size;
                check_size(size.width() as u32, size.height() as u32).map_err(bad)?;
                (size.width() as u32, size.height() as u32, image.layer_data.channel_data.pixels.1)
            }
            _ => return Err(bad("not a .hdr or .exr file".into())),
        };
        if radiance.iter().any(|c: &Vec3| !c.is_finite() || c.min_element() < 0.0) {
            return Err(bad("radiance values must be finite and not negative".into()));
        }
        let env = Environment { name, width, height, radiance };
        Ok(env.fit_width(MAX_ENV_WIDTH))
    }

    /// The environment halved (2×2 box filter; odd sizes repeat the last row/column).
    fn half(&self) -> Environment {
        let (w, h) = ((self.width / 2).max(1), (self.height / 2).max(1));
        let at = |x: u32, y: u32| self.radiance[(y.min(self.height - 1) * self.width + x.min(self.width - 1)) as usize];
        let radiance = (0..w * h)
            .map(|i| {
                let (x, y) = (2 * (i % w), 2 * (i / w));
                (at(x, y) + at(x + 1, y) + at(x, y + 1) + at(x + 1, y + 1)) * 0.25
            })
            .collect();
        Environment { name: self.name.clone(), width: w, height: h, radiance }
    }

    fn fit_width(self, max_width: u32) -> Environment {
        let mut env = self;
        while env.width > max_width {
            env = env.half();
        }
        env
    }

    /// Bilinear radiance at continuous image position p (longitude wraps, latitude clamps).
    fn bilinear(&self, p: Vec2) -> Vec3 {
        let q = p - 0.5;
        let (x0, y0) = (q.x.floor(), q.y.floor());
        let (fx, fy) = (q.x - x0, q.y - y0);
        let at = |x: i64, y: i64| {
            let x = x.rem_euclid(self.width as i64) as u32;
            let y = y.clamp(0, self.height as i64 - 1) as u32;
            self.radiance[(y * self.width + x) as usize]
        };
        let (x0, y0) = (x0 as i64, y0 as i64);
        (at(x0, y0) * (1.0 - fx) + at(x0 + 1, y0) * fx) * (1.0 - fy)
            + (at(x0, y0 + 1) * (1.0 - fx) + at(x0 + 1, y0 + 1) * fx) * fy
    }

    /// Everything the fragment stage reads (see the module doc).
    pub fn prepare(&self) -> PreparedEnvironment {
        let mut pyramid = vec![self.clone()];
        while pyramid.last().is_some_and(|e| e.width > 1 || e.height > 1) {
            let next = pyramid.last().unwrap().half();
            pyramid.push(next);
        }
        let mut texels: Vec<u32> = Vec::new();
        let mut levels = [[0u32; 3]; ENV_LEVELS];
        for (k, level) in levels.iter_mut().enumerate() {
            let roughness = k as f32 / (ENV_LEVELS - 1) as f32;
            // Level 0: the radiance; then half, quarter … of its width, at least 8 × 4.
            let (w, h) = if k == 0 {
                (self.width, self.height)
            } else {
                ((self.width >> (k + 1)).max(8), (self.height >> (k + 1)).max(4))
            };
            *level = [texels.len() as u32, w, h];
            let rows: Vec<Vec<u32>> = parallel_rows(h, |y| {
                (0..w)
                    .map(|x| {
                        let d = direction_at(x as f32 + 0.5, y as f32 + 0.5, w, h);
                        let c = if k == 0 {
                            self.radiance[(y * w + x) as usize]
                        } else {
                            prefilter(&pyramid, d, roughness)
                        };
                        rgb9e5(c)
                    })
                    .collect()
            });
            texels.extend(rows.into_iter().flatten());
        }
        let lut_offset = texels.len() as u32;
        for j in 0..LUT_SIZE {
            for i in 0..LUT_SIZE {
                let nv = (i as f32 + 0.5) / LUT_SIZE as f32;
                let roughness = (j as f32 + 0.5) / LUT_SIZE as f32;
                let (a, b) = split_sum(nv, roughness);
                texels.push(pack_half2(a, b));
            }
        }
        // Irradiance from a level of at most 64 texels across (box filtering keeps the energy).
        let small = pyramid.iter().find(|e| e.width <= 64).unwrap_or(&pyramid[0]);
        PreparedEnvironment {
            name: self.name.clone(),
            texels,
            levels,
            lut_offset,
            sh: irradiance_sh(small),
            background: false,
        }
    }
}

/// RGB9E5 (the shared-exponent format of EXT_texture_shared_exponent), rounding to nearest;
/// channels clamped to [0, 65,408].
pub fn rgb9e5(c: Vec3) -> u32 {
    const MAX: f32 = 511.0 / 512.0 * 65536.0;
    let c = c.clamp(Vec3::ZERO, Vec3::splat(MAX));
    let max = c.max_element();
    let mut exp = (max.log2().floor().max(-16.0) as i32) + 1 + 15;
    let scale = |e: i32| 2f32.powi(e - 15 - 9);
    if (max / scale(exp) + 0.5).floor() >= 512.0 {
        exp += 1;
    }
    let m = |x: f32| ((x / scale(exp) + 0.5).floor() as u32).min(511);
    m(c.x) | m(c.y) << 9 | m(c.z) << 18 | (exp.clamp(0, 31) as u32) << 27
}

/// The colour of an RGB9E5 texel (`env_texel` in surface.wgsl).
pub fn rgb9e5_decode(bits: u32) -> Vec3 {
    let scale = 2f32.powi((bits >> 27) as i32 - 15 - 9);
    Vec3::new((bits & 511) as f32, (bits >> 9 & 511) as f32, (bits >> 18 & 511) as f32) * scale
}

/// Two half floats, a in the low 16 bits (WGSL's `pack2x16float`).
pub fn pack_half2(a: f32, b: f32) -> u32 {
    half::f16::from_f32(a).to_bits() as u32 | (half::f16::from_f32(b).to_bits() as u32) << 16
}

/// The inverse of [`pack_half2`] (`unpack2x16float`).
pub fn unpack_half2(bits: u32) -> Vec2 {
    Vec2::new(half::f16::from_bits(bits as u16).to_f32(), half::f16::from_bits((bits >> 16) as u16).to_f32())
}

fn check_size(width: u32, height: u32) -> std::result::Result<(), String> {
    if width == 0 || height == 0 || (width as u64) * (height as u64) > MAX_ENV_TEXELS {
        return Err(format!("{width}×{height} texels: an environment must have 1 to {MAX_ENV_TEXELS} texels"));
    }
    Ok(())
}

/// Rows 0..h computed on the machine's cores, in order.
fn parallel_rows<T: Send>(h: u32, row: impl Fn(u32) -> T + Sync) -> Vec<T> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(h.max(1) as usize);
    let chunk = (h as usize).div_ceil(threads);
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let row = &row;
                s.spawn(move || {
                    ((t * chunk) as u32..((t + 1) * chunk).min(h as usize) as u32).map(row).collect::<Vec<T>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("environment worker")).collect()
    })
}

/// The i-th of n Hammersley points in [0, 1)².
fn hammersley(i: u32, n: u32) -> Vec2 {
    Vec2::new((i as f32 + 0.5) / n as f32, i.reverse_bits() as f32 * (1.0 / 4_294_967_296.0))
}

/// A GGX half vector around n for α = roughness² from a uniform point, and its D.
fn ggx_sample(xi: Vec2, n: Vec3, alpha: f32) -> (Vec3, f32) {
    let a2 = alpha * alpha;
    let phi = std::f32::consts::TAU * xi.y;
    let cos_t = ((1.0 - xi.x) / (1.0 + (a2 - 1.0) * xi.x)).max(0.0).sqrt();
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let up = if n.y.abs() < 0.999 { Vec3::Y } else { Vec3::X };
    let t = up.cross(n).normalize();
    let b = n.cross(t);
    let h = (t * (sin_t * phi.cos()) + b * (sin_t * phi.sin()) + n * cos_t).normalize();
    let k = cos_t * cos_t * (a2 - 1.0) + 1.0;
    (h, a2 / (std::f32::consts::PI * k * k))
}

/// The GGX-convolved radiance around direction r (N = V = R).
fn prefilter(pyramid: &[Environment], r: Vec3, roughness: f32) -> Vec3 {
    let alpha = (roughness * roughness).max(1e-3);
    let base = &pyramid[0];
    let texel_solid_angle = 4.0 * std::f32::consts::PI / (base.width * base.height) as f32;
    let (mut sum, mut weight) = (Vec3::ZERO, 0.0);
    for i in 0..PREFILTER_SAMPLES {
        let (h, d) = ggx_sample(hammersley(i, PREFILTER_SAMPLES), r, alpha);
        let l = 2.0 * r.dot(h) * h - r;
        let nl = r.dot(l);
        if nl <= 0.0 {
            continue;
        }
        // pdf of l = D·(n·h)/(4·(v·h)) = D/4 with n = v.
        let sample_solid_angle = 4.0 / (PREFILTER_SAMPLES as f32 * d.max(1e-6));
        let lod = (0.5 * (sample_solid_angle / texel_solid_angle).log2() + 1.0).clamp(0.0, (pyramid.len() - 1) as f32);
        let (l0, t) = (lod.floor() as usize, lod.fract());
        let read = |k: usize| {
            let e = &pyramid[k.min(pyramid.len() - 1)];
            e.bilinear(position_of(l, e.width, e.height))
        };
        let c = read(l0) * (1.0 - t) + read(l0 + 1) * t;
        sum += c * nl;
        weight += nl;
    }
    if weight > 0.0 {
        sum / weight
    } else {
        Vec3::ZERO
    }
}

/// Smith's separable GGX masking for one direction (as in `brdf`).
fn smith(nx: f32, a2: f32) -> f32 {
    2.0 * nx / (nx + (a2 + (1.0 - a2) * nx * nx).sqrt())
}

/// The split-sum table entry (A, B) at n·v and roughness.
pub fn split_sum(nv: f32, roughness: f32) -> (f32, f32) {
    let alpha = (roughness * roughness).max(1e-3);
    let a2 = alpha * alpha;
    let v = Vec3::new((1.0 - nv * nv).max(0.0).sqrt(), 0.0, nv);
    let (mut a, mut b) = (0.0, 0.0);
    for i in 0..LUT_SAMPLES {
        let (h, _) = ggx_sample(hammersley(i, LUT_SAMPLES), Vec3::Z, alpha);
        let l = 2.0 * v.dot(h) * h - v;
        let (nl, nh, vh) = (l.z, h.z.max(0.0), v.dot(h).max(0.0));
        if nl > 0.0 {
            // f·n·l/pdf with pdf = D·nh/(4·vh): G·vh/(nh·nv) (the F factor split off).
            let g_vis = smith(nl, a2) * smith(nv, a2) * vh / (nh * nv).max(1e-8);
            let fc = (1.0 - vh).powi(5);
            a += (1.0 - fc) * g_vis;
            b += fc * g_vis;
        }
    }
    (a / LUT_SAMPLES as f32, b / LUT_SAMPLES as f32)
}

/// The real spherical harmonics of degree ≤ 2 at unit direction d.
pub fn sh_basis(d: Vec3) -> [f32; 9] {
    [
        0.282_095,
        0.488_603 * d.y,
        0.488_603 * d.z,
        0.488_603 * d.x,
        1.092_548 * d.x * d.y,
        1.092_548 * d.y * d.z,
        0.315_392 * (3.0 * d.z * d.z - 1.0),
        1.092_548 * d.x * d.z,
        0.546_274 * (d.x * d.x - d.y * d.y),
    ]
}

/// E(n)/π as SH coefficients: the radiance projected (solid-angle weighted), times Â_l/π.
fn irradiance_sh(env: &Environment) -> [Vec3; 9] {
    let mut sh = [Vec3::ZERO; 9];
    let (w, h) = (env.width, env.height);
    let mut total = 0.0;
    for y in 0..h {
        // The exact solid angle of the row's texels (so a uniform map integrates to 4π).
        let top = (0.5 - y as f32 / h as f32) * std::f32::consts::PI;
        let bottom = (0.5 - (y + 1) as f32 / h as f32) * std::f32::consts::PI;
        let d_omega = (top.sin() - bottom.sin()) * std::f32::consts::TAU / w as f32;
        for x in 0..w {
            let d = direction_at(x as f32 + 0.5, y as f32 + 0.5, w, h);
            let c = env.radiance[(y * w + x) as usize];
            for (s, b) in sh.iter_mut().zip(sh_basis(d)) {
                *s += c * (b * d_omega);
            }
            total += d_omega;
        }
    }
    debug_assert!((total - 4.0 * std::f32::consts::PI).abs() < 1e-2);
    let band = [1.0, 2.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0, 0.25, 0.25, 0.25, 0.25, 0.25];
    for (s, a) in sh.iter_mut().zip(band) {
        *s *= a;
    }
    sh
}

/// E(n)/π from the coefficients, clamped at 0 (`env_irradiance` in surface.wgsl).
pub fn irradiance(sh: &[Vec3; 9], n: Vec3) -> Vec3 {
    sh.iter().zip(sh_basis(n)).fold(Vec3::ZERO, |a, (s, b)| a + *s * b).max(Vec3::ZERO)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_and_positions_are_inverse() {
        for (x, y) in [(3.5, 2.5), (100.25, 60.0), (255.0, 127.5), (0.5, 64.0)] {
            let d = direction_at(x, y, 256, 128);
            assert!((d.length() - 1.0).abs() < 1e-5);
            let p = position_of(d, 256, 128);
            assert!((p - Vec2::new(x, y)).length() < 1e-2, "{x},{y} -> {p}");
        }
        // The centre looks along −z, the top row up.
        assert!((direction_at(128.0, 64.0, 256, 128) - Vec3::NEG_Z).length() < 1e-5);
        assert!(direction_at(128.0, 0.0, 256, 128).y > 0.999);
    }

    /// The SH irradiance against brute-force cosine integration of the same map.
    #[test]
    fn sh_irradiance_matches_a_brute_force_cosine_integral() {
        let env = Environment::neutral().half().half();
        let sh = irradiance_sh(&env);
        for n in [Vec3::Y, Vec3::NEG_Y, Vec3::X, Vec3::new(0.3, 0.5, -0.8).normalize()] {
            let mut e = Vec3::ZERO;
            for y in 0..env.height {
                let top = (0.5 - y as f32 / env.height as f32) * std::f32::consts::PI;
                let bottom = (0.5 - (y + 1) as f32 / env.height as f32) * std::f32::consts::PI;
                let d_omega = (top.sin() - bottom.sin()) * std::f32::consts::TAU / env.width as f32;
                for x in 0..env.width {
                    let d = direction_at(x as f32 + 0.5, y as f32 + 0.5, env.width, env.height);
                    e += env.radiance[(y * env.width + x) as usize] * d.dot(n).max(0.0) * d_omega;
                }
            }
            let want = e / std::f32::consts::PI;
            let got = irradiance(&sh, n);
            assert!((got - want).abs().max_element() < 0.05 * want.max_element(), "n {n}: SH {got}, integral {want}");
        }
    }

    /// The split-sum table: A + B is the white directional albedo of the lobe, ≤ 1, near 1 for a
    /// smooth surface, lower for a rough one at grazing angles; B grows towards grazing.
    #[test]
    fn the_split_sum_table_has_the_known_shape() {
        let (a, b) = split_sum(0.9, 0.05);
        assert!((a + b - 1.0).abs() < 0.02, "smooth: {a} + {b}");
        let (a1, b1) = split_sum(0.1, 1.0);
        assert!(a1 + b1 < 0.8 && a1 + b1 > 0.3, "rough grazing: {a1} + {b1}");
        assert!(split_sum(0.1, 0.5).1 > split_sum(0.9, 0.5).1);
    }

    #[test]
    fn shared_exponent_and_half_packing_round_trip() {
        for c in [Vec3::new(0.7, 0.01, 3.0), Vec3::new(6496.0, 40.0, 0.0), Vec3::splat(1e-5), Vec3::ZERO] {
            let d = rgb9e5_decode(rgb9e5(c));
            assert!((d - c).abs().max_element() <= c.max_element() / 512.0 + 1e-7, "{c} -> {d}");
        }
        let ab = unpack_half2(pack_half2(0.8125, 0.0421));
        assert!((ab - Vec2::new(0.8125, 0.0421)).abs().max_element() < 1e-4, "{ab}");
    }

    #[test]
    fn a_uniform_environment_prefilters_to_itself() {
        let p = Environment::uniform(Vec3::splat(0.7)).prepare();
        for &t in &p.texels[..p.lut_offset as usize] {
            assert!((rgb9e5_decode(t) - Vec3::splat(0.7)).abs().max_element() < 2e-3, "{:?}", rgb9e5_decode(t));
        }
        assert!(
            (irradiance(&p.sh, Vec3::new(0.2, -0.9, 0.1).normalize()) - Vec3::splat(0.7)).abs().max_element() < 2e-3
        );
    }
}
