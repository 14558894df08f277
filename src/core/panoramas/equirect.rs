//! The full sphere, equirectangular (`--panorama equirect`): omni-directional stereo as Google's
//! ODS and Blender Cycles' spherical stereo make it, 360° × 180° per eye, W × W/2. The eye model
//! and its forward map are the sphere's (`core::panoramas::sphere`); the image is linear in
//! longitude and latitude: x = (λ/2π + ½)·W, y = (½ − φ/π)·H. WGSL:
//! `shaders/shared/projection_sphere.wgsl`.

use crate::core::panoramas::panorama::{EyeModel, EyePacking, ImageMap, Panorama, PanoramaKind};
use crate::core::panoramas::projection::Projection;

/// The full sphere, equirectangular.
pub struct Equirect;

impl Projection {
    /// The full-sphere panorama of `width` × `width`/2 pixels per eye, parallel rays, Blender's
    /// pole merge.
    pub fn equirect(width: u32) -> Projection {
        Projection::of(Equirect.kind(), width)
    }
}

/// On the sphere the latitude atan2(y, √(r² − e²)) ≥ atan(y/r): a point with |y| > k·r,
/// k = 1/tan(π/2H), lies beyond the centre of the first (last) pixel row, which no rasterized
/// sample reaches, for every eye offset.
pub(crate) fn sphere_vertical_limit(p: &Projection) -> f32 {
    1.0 / (0.5 * std::f32::consts::PI / p.height as f32).tan()
}

impl Panorama for Equirect {
    fn kind(&self) -> PanoramaKind {
        PanoramaKind::Equirect
    }

    fn wgsl_name(&self) -> &'static str {
        "PANORAMA_EQUIRECT"
    }

    fn shader_bits(&self) -> u32 {
        2
    }

    fn eye_model(&self) -> EyeModel {
        EyeModel::Sphere
    }

    fn image_map(&self) -> ImageMap {
        ImageMap::Linear
    }

    fn player_tag(&self) -> Option<&'static str> {
        Some("360")
    }

    fn eye_packing(&self) -> EyePacking {
        EyePacking::TopBottom
    }

    fn default_size(&self, width: u32) -> [u32; 2] {
        [width, width / 2]
    }

    fn vertical_limit(&self, p: &Projection) -> f32 {
        sphere_vertical_limit(p)
    }
}
