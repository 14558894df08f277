//! VR180 (`--panorama vr180`): the sphere's front half, equirectangular 180° × 180° per eye
//! (W = H), the same eye model as the full sphere (`core::panoramas::sphere`); longitudes beyond
//! ±90° fall outside the image, whose width spans half a turn: x = (λ/π + ½)·W. WGSL:
//! `shaders/shared/projection_sphere.wgsl`.

use crate::core::panoramas::equirect::sphere_vertical_limit;
use crate::core::panoramas::panorama::{EyeModel, EyePacking, ImageMap, Panorama, PanoramaKind};
use crate::core::panoramas::projection::Projection;

/// The sphere's front half.
pub struct Vr180;

impl Projection {
    /// VR180: the sphere's front half, `width` × `width` pixels per eye, parallel rays, Blender's
    /// pole merge.
    pub fn vr180(width: u32) -> Projection {
        Projection::of(Vr180.kind(), width)
    }
}

impl Panorama for Vr180 {
    fn kind(&self) -> PanoramaKind {
        PanoramaKind::Vr180
    }

    fn wgsl_name(&self) -> &'static str {
        "PANORAMA_VR180"
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

    fn turn_share(&self) -> Option<f32> {
        Some(0.5)
    }

    fn player_tag(&self) -> Option<&'static str> {
        Some("180")
    }

    fn eye_packing(&self) -> EyePacking {
        EyePacking::SideBySide
    }

    fn default_size(&self, width: u32) -> [u32; 2] {
        [width, width]
    }

    fn vertical_limit(&self, p: &Projection) -> f32 {
        sphere_vertical_limit(p)
    }
}
