//! The panoramas twister renders (`--panorama`) behind one interface, [`Panorama`] (as pbrt's
//! `Camera`): each is a type in its own file — `Cylinder` (cylinder.rs), `Equirect`, `Vr180`,
//! `Fisheye`, `Cubemap`, `Cave` — with its forward map and inverse, its image's facts, its WGSL
//! module's code and what the pipeline asks of it. [`PanoramaKind`] is the name a setting chooses
//! (the command line, a settings file, `core::panoramas::kind`); its `model` is its type, from
//! the registry (`core::panoramas::registry`). Adding a panorama: its file, a line in the
//! registry and a variant of the kind (docs/ARCHITECTURE.md, *How to add … a panorama*).
//!
//! The maps' defaults are the full sphere's eye model (`core::panoramas::sphere`), whose rays
//! four of the six panoramas draw, in the linear image map; a panorama overrides what differs.
//!
//! A type's parameters are the [`Projection`]'s (the settings' `view.projection`): R_T, d_e, the
//! image's size and each panorama's own (the fisheye's field of view, the CAVE's wall).

use glam::Vec3;

pub use crate::core::panoramas::kind::PanoramaKind;
use crate::core::panoramas::projection::{azimuth, linear_pixel, linear_screen, Eye, Projected, Projection};
use crate::core::panoramas::sphere::direction;
use crate::error::Result;

/// Whose eyes look: where they stand and which rays they cast.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EyeModel {
    /// The cylinder's: eyes on the circle of radius d_e about the axis, each looking along its
    /// tangent (seed 002 eq. 1–4), or a tracked head's (`core::panoramas::head`).
    Circle,
    /// The full sphere's omni-directional stereo (`core::panoramas::sphere`): the eye offset
    /// fades towards the poles, the rays may converge.
    Sphere,
    /// A tracked head's two fixed eyes before a plane (one pinhole per eye).
    Pinhole,
}

/// How an image's pixels map the screen point (u, v) (the image maps of projection.wgsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageMap {
    /// x linear in u (wrapping at a turn of `turn_px`), y linear in v: the cylinder, the
    /// sphere's equirectangular images.
    Linear,
    /// The fisheye's equidistant azimuthal image about the dome's axis.
    Fisheye,
    /// The cubemap's six faces, each a pinhole's image.
    Cubemap,
    /// (u, v) are the image position itself (the CAVE's wall).
    Plane,
}

/// How a file holds the two eyes by default (`--layout`'s default for the panorama).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EyePacking {
    /// One image per eye.
    Separate,
    /// Left above right, one image.
    TopBottom,
    /// Left beside right, one image.
    SideBySide,
}

/// A panorama: the forward map of a viewer-frame point to an eye's image and its inverse, the
/// image's facts and what the pipeline asks of it. Every map takes the frame's [`Projection`],
/// whose fields are its parameters; the [`Projection`]'s methods of the same names dispatch to
/// the panorama its `panorama` names.
pub trait Panorama: Sync {
    /// The kind that names it.
    fn kind(&self) -> PanoramaKind;

    /// The panorama's constant in the WGSL projection module (`PANORAMA_CYLINDER`).
    fn wgsl_name(&self) -> &'static str;

    /// `PANORAMAS` for the drawing stages' WGSL (projection.wgsl): the bits of the image maps
    /// and eye models its pipelines compile in (1 the cylinder's, 2 the sphere's, 4 the
    /// fisheye's, 8 the cubemap's, 16 the CAVE's).
    fn shader_bits(&self) -> u32;

    fn eye_model(&self) -> EyeModel;

    fn image_map(&self) -> ImageMap;

    /// The share of a full turn of azimuth the image's width spans (1; ½ for VR180); None where
    /// the image has no seam (x never wraps).
    fn turn_share(&self) -> Option<f32> {
        Some(1.0)
    }

    /// The tag VR players detect in a file name (`_360`, `_180`); None where it is no player
    /// format.
    fn player_tag(&self) -> Option<&'static str> {
        None
    }

    /// How a file holds the two eyes by default.
    fn eye_packing(&self) -> EyePacking {
        EyePacking::Separate
    }

    /// The image size per eye, pixels, of a frame `width` wide (`--width` alone).
    fn default_size(&self, width: u32) -> [u32; 2];

    /// Whether the slit renderer (`slit:W`, the reference) pastes this panorama's slits: its
    /// columns (or the sphere's tiles) in the linear image map.
    fn has_slits(&self) -> bool {
        self.image_map() == ImageMap::Linear
    }

    /// Whether an edge split without measuring it (`vertex`, `fixed:N`) is drawn within the
    /// image (the fisheye bends edges beyond its rim round the circle: not).
    fn takes_unmeasured_edges(&self) -> bool {
        true
    }

    /// Whether every method draws it as one pinhole per eye, without subdivision: where the
    /// eyes are pinholes before a plane (the CAVE).
    fn drawn_as_pinhole(&self) -> bool {
        self.eye_model() == EyeModel::Pinhole
    }

    /// The panorama's own settings (its field of view, its wall, its grid), each error naming
    /// its field.
    fn validate(&self, _p: &Projection) -> Result<()> {
        Ok(())
    }

    /// Whether an eye sees viewer-frame point `q` (finite) at all: the sphere's, r beyond the
    /// eye offset at its altitude.
    fn sees(&self, p: &Projection, q: Vec3) -> bool {
        p.sphere_sees(q)
    }

    /// The screen point (u, v) and depth of `q` for `eye`, u unwrapped about the azimuth θ
    /// the caller gives; finite where no eye sees it. The sphere's: longitude and latitude of
    /// the eye ray that reaches `q`.
    fn project_with_azimuth(&self, p: &Projection, q: Vec3, theta: f32, eye: Eye) -> Projected {
        p.sphere_project(q, theta, eye)
    }

    /// Continuous image coordinates (x right, y down, pixel centres at +0.5) of screen point
    /// (u, v): the linear map.
    fn to_pixel(&self, p: &Projection, u: f32, v: f32) -> [f32; 2] {
        linear_pixel(p, u, v)
    }

    /// The screen point (u, v) at the centre of pixel (column, row): the linear map's.
    fn pixel_to_screen(&self, p: &Projection, column: f32, row: f32) -> (f32, f32) {
        linear_screen(p, column, row)
    }

    /// Pixels per unit of v (where it is the smallest): the sphere's rows, H/π per radian of
    /// latitude.
    fn pixels_per_v(&self, p: &Projection) -> f32 {
        p.height as f32 / std::f32::consts::PI
    }

    /// The tangent of the half vertical angle that `--fit` and the screen-filling built-ins fill.
    fn fill_tan(&self, _p: &Projection) -> f32 {
        30f32.to_radians().tan()
    }

    /// The unit direction, seen from the centre (the head), of screen point (u, v): the
    /// sphere's longitude u, latitude v.
    fn screen_direction(&self, _p: &Projection, u: f32, v: f32) -> Vec3 {
        direction(u, v)
    }

    /// The slope k such that a point with |y| > k·r shows in no pixel row (f32::MAX: none).
    fn vertical_limit(&self, _p: &Projection) -> f32 {
        f32::MAX
    }

    /// The eye point and unit direction of the ray through screen point (u, v): the sphere's
    /// (Cycles' spherical stereo).
    fn ray(&self, p: &Projection, eye: Eye, u: f32, v: f32) -> (Vec3, Vec3) {
        p.sphere_ray(u, v, eye)
    }

    /// Where `eye` sees viewer-frame point `q`: the screen point and depth; None where it does
    /// not ([`Panorama::sees`]) or `q` is not finite.
    fn project(&self, p: &Projection, q: Vec3, eye: Eye) -> Option<Projected> {
        (q.is_finite() && self.sees(p, q)).then(|| self.project_with_azimuth(p, q, azimuth(q), eye))
    }

    /// Whether image position (x, y) shows the panorama (the fisheye: inside its circle).
    fn shows_pixel(&self, _p: &Projection, _x: f32, _y: f32) -> bool {
        true
    }

    /// How far, in pixels, a drawn edge beyond the image's rim may dip towards its centre
    /// (the fisheye's chords: `core::panoramas::fisheye`); 0 where edges have no rim to cross.
    fn chord_dip_px(&self, _p: &Projection, _error_split: bool, _edge_px: f32, _max_error_px: f32) -> f32 {
        0.0
    }

    /// cos β of the cone about the point opposite the image's axis whose triangles the
    /// subdivision drops (the fisheye's folded ring: `core::panoramas::fisheye`); None: none.
    fn antipode_cone(&self, _p: &Projection, _dip_px: f32) -> Option<f32> {
        None
    }

    /// The image the subdivision measures its edges on: the panorama's own, or one of the same
    /// eye model with the same resolution (the cubemap's: the sphere's).
    fn measured(&self, p: &Projection) -> Projection {
        *p
    }

    /// The width of the squares no tile column of a frame drawn in tiles may straddle (the
    /// cubemap's faces); 0: none.
    fn tile_face(&self, _p: &Projection) -> u32 {
        0
    }

    /// The viewer-frame point at `depth` that `eye` sees at screen point (u, v): along the ray
    /// by default; the cylinder's eq. 1–4 inverted at the distance `depth` from its axis.
    fn unproject(&self, p: &Projection, u: f32, v: f32, depth: f32, eye: Eye) -> Vec3 {
        let (origin, ray) = self.ray(p, eye, u, v);
        origin + depth * ray
    }
}
