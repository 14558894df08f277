//! The full sphere's eye model and forward map, shared by the panoramas that draw its rays
//! (`equirect`, `vr180`, `fisheye`, `cubemap`: omni-directional stereo as Google's
//! ODS and Blender Cycles' spherical stereo make it). A pixel at longitude λ (column, 0 straight
//! ahead, positive to the right) and latitude φ (row, +90° at the top) looks along
//! D = (cos φ sin λ, sin φ, −cos φ cos λ) from the eye point E = s·d·side, side = (cos λ, 0, sin λ)
//! = normalize(D × up) (Cycles' `spherical_stereo_position`, s = +1 for the right eye, which stands
//! on the right of its view). The offset d = f(|φ|)·d_e fades near the poles (pole merge: f = 1
//! below FROM, cos(π/2·(|φ| − FROM)/(TO − FROM)) between, 0 beyond TO). With parallel convergence
//! the ray is D; converging on the sphere of radius c it is normalize(c·D − E)
//! (`spherical_stereo_direction`): the ray from E through the point c·D.
//!
//! Forward, for a point P at horizontal radius r, height y, azimuth θ, and a fixed offset d: the
//! ray meets P when P = E + t·(c·D − E); E ⟂ D gives P·E = (1 − t)·d², and |c·D| = c gives
//! (c² + d²)·t² − 2d²·t − (|P|² − d²) = 0. With e = (1 − t)·d (e = d for parallel rays):
//!
//! ```text
//!   λ = θ − s·asin(e/r),   φ = atan2(y, √(r² − e²)),   depth |P − E| = √(r² + y² + d² − 2·d·e)
//! ```
//!
//! (for parallel rays λ = θ − s·asin(d_e/r): the cylinder's u without its screen term). With pole
//! merge, d depends on φ, which depends on d: φ is the root of φ = φ(f(φ)·d_e), found by Newton
//! steps between FROM and TO (the closed forms hold when the altitude at full offset is below
//! FROM or at zero offset above TO). x = (λ/2π + ½)·W, y = (½ − φ/π)·H.
//!
//! The WGSL twin is the sphere's part of `shaders/shared/projection.wgsl`.

use glam::Vec3;

use crate::core::panoramas::projection::{horizontal_radius, Eye, Projected, Projection};

/// The most Newton steps the pole merge's eye offset takes ([`Projection::sphere_eye_offset`]).
pub const SPHERE_NEWTON_STEPS: u32 = 4;
/// A Newton step that moves the altitude by at most this many radians ends the pole merge's
/// steps: the next would move it by about its square (10⁻¹⁰ rad, far below a pixel).
pub const SPHERE_NEWTON_TOLERANCE: f32 = 1e-5;

/// The unit direction of longitude `lon`, latitude `lat`.
pub fn direction(lon: f32, lat: f32) -> Vec3 {
    Vec3::new(lat.cos() * lon.sin(), lat.sin(), -lat.cos() * lon.cos())
}

impl Projection {
    /// The sphere's pole merge: the factor on the eye offset for a ray of altitude `a` radians
    /// (≥ 0). `pole_fade` in projection.wgsl.
    pub fn pole_fade(&self, a: f32) -> f32 {
        match self.pole_merge {
            None => 1.0,
            Some((from, to)) => {
                let (from, to) = (from.to_radians(), to.to_radians());
                if a <= from {
                    1.0
                } else if a >= to {
                    0.0
                } else {
                    (std::f32::consts::FRAC_PI_2 * (a - from) / (to - from)).cos()
                }
            }
        }
    }

    /// e, the signed distance of the eye's ray from P's vertical line along `side` (e = d for
    /// parallel rays), for eye offset d ≥ 0: see the module doc. `sphere_e` in projection.wgsl.
    fn sphere_e(&self, r: f32, y: f32, d: f32) -> f32 {
        self.sphere_e_slope(r, y, d).0
    }

    /// e and de/dd. Converging: S = √(d⁴ + (d² + c²)(|P|² − d²)), t = (d² + S)/(d² + c²),
    /// e = (1 − t)·d, so S' = d(|P|² − c²)/S, t' = ((2d + S')(d² + c²) − 2d(d² + S))/(d² + c²)²,
    /// e' = 1 − t − d·t'.
    fn sphere_e_slope(&self, r: f32, y: f32, d: f32) -> (f32, f32) {
        match self.convergence {
            None => (d, 1.0),
            Some(c) => {
                let (d2, c2, p2) = (d * d, c * c, r * r + y * y);
                let s = (d2 * d2 + (d2 + c2) * (p2 - d2)).max(0.0).sqrt();
                let t = (d2 + s) / (d2 + c2);
                let ds = if s > 0.0 { d * (p2 - c2) / s } else { 0.0 };
                let dt = ((2.0 * d + ds) * (d2 + c2) - 2.0 * d * (d2 + s)) / ((d2 + c2) * (d2 + c2));
                ((1.0 - t) * d, 1.0 - t - d * dt)
            }
        }
    }

    /// Longitude, latitude and depth |P − E| of a point for eye sign s at a fixed eye offset d.
    /// `sphere_at_offset` in projection.wgsl.
    pub(super) fn sphere_at_offset(&self, r: f32, y: f32, theta: f32, s: f32, d: f32) -> (f32, f32, f32) {
        let e = self.sphere_e(r, y, d);
        let q = if r > 0.0 { (e / r).clamp(-1.0, 1.0) } else { 0.0 };
        let lon = theta - s * q.asin();
        let lat = y.atan2((r * r - e * e).max(0.0).sqrt());
        let depth = (r * r + y * y + d * d - 2.0 * d * e).max(0.0).sqrt();
        (lon, lat, depth)
    }

    /// The altitude |φ| at which a point is seen at eye offset d, and its slope dφ/dd:
    /// φ = atan2(|y|, h), h = √(r² − e²), so dφ/dd = |y|·e·e' / (h·(h² + y²)).
    fn sphere_altitude(&self, r: f32, y: f32, d: f32) -> (f32, f32) {
        let (e, de) = self.sphere_e_slope(r, y, d);
        let h = (r * r - e * e).max(1e-30).sqrt();
        (y.abs().atan2(h), y.abs() * e * de / (h * (h * h + y * y)))
    }

    /// The eye offset d = f(|φ|)·d_e at which a point is seen, the same for both eyes: the root
    /// of g(a) = A(f(a)·d_e) − a, A the altitude at offset d (see the module doc). The closed
    /// form d_e where the altitude at full offset is below FROM; else Newton steps from that
    /// altitude (clamped to [FROM, TO]; the root lies between it and the altitude seen from the
    /// centre, A growing with d), at most [`SPHERE_NEWTON_STEPS`], until one moves a by at most
    /// [`SPHERE_NEWTON_TOLERANCE`] (g' = A'·d_e·f' − 1 ≤ −1: g falls steeply, and the steps
    /// converge fast: the next would move a by about the square of the last). A point seen
    /// beyond TO from the centre ends at TO, whose fade is 0. The GPU twin (`sphere_eye_offset`
    /// in projection_sphere.wgsl) runs the same steps in a loop, which ends for a group of
    /// lanes once every lane's steps have converged (two steps, most often, on lavapipe).
    pub fn sphere_eye_offset(&self, r: f32, y: f32) -> f32 {
        let de = self.eye_radius;
        let Some((from, to)) = self.pole_merge else {
            return de;
        };
        let (from, to) = (from.to_radians(), to.to_radians());
        let full = self.sphere_altitude(r, y, de).0;
        if full <= from {
            return de;
        }
        let k = std::f32::consts::FRAC_PI_2 / (to - from);
        let mut a = full.clamp(from, to);
        for _ in 0..SPHERE_NEWTON_STEPS {
            let (altitude, slope) = self.sphere_altitude(r, y, self.pole_fade(a) * de);
            let g = altitude - a;
            let dg = slope * de * (-k * (k * (a - from)).sin()) - 1.0;
            let next = (a - g / dg).clamp(from, to);
            let converged = (next - a).abs() <= SPHERE_NEWTON_TOLERANCE;
            a = next;
            if converged {
                break;
            }
        }
        self.pole_fade(a) * de
    }

    /// Whether every ray to the segment ab comes from the centre: no eye offset at all (a mono
    /// camera), or both ends in one of the pole merge's cones beyond TO (seen from the centre at
    /// an altitude of at least TO, on the same side: the cone is convex, so the segment lies in
    /// it), where the offset has faded to 0. A pinhole at the centre (the cubemap's faces drawn
    /// with w the distance along the ray) draws such a segment exactly.
    pub fn seen_from_centre(&self, a: Vec3, b: Vec3) -> bool {
        if self.eye_radius == 0.0 {
            return true;
        }
        let Some((_, to)) = self.pole_merge else {
            return false;
        };
        let to = to.to_radians();
        let merged = |p: Vec3| p.y != 0.0 && p.y.abs().atan2(horizontal_radius(p)) >= to;
        merged(a) && merged(b) && (a.y > 0.0) == (b.y > 0.0)
    }

    /// Whether an eye's ray reaches `p` on the sphere: r > |e| (a point on the axis only where the
    /// offset has faded to 0).
    pub(super) fn sphere_sees(&self, p: Vec3) -> bool {
        let r = horizontal_radius(p);
        let e = self.sphere_e(r, p.y, self.sphere_eye_offset(r, p.y));
        r > e.abs() || (r == 0.0 && e == 0.0 && p.y != 0.0)
    }

    /// Longitude, latitude and depth of `p` for `eye`, the longitude unwrapped about the
    /// caller's azimuth θ (see the module doc).
    pub(super) fn sphere_project(&self, p: Vec3, theta: f32, eye: Eye) -> Projected {
        let r = horizontal_radius(p);
        let d = self.sphere_eye_offset(r, p.y);
        let (lon, lat, depth) = self.sphere_at_offset(r, p.y, theta, eye.sign(), d);
        Projected { u: lon, v: lat, depth }
    }

    /// The eye point and ray direction of the sphere's pixel at longitude `lon`, latitude `lat`
    /// (Cycles' spherical stereo, see the module doc).
    pub fn sphere_ray(&self, lon: f32, lat: f32, eye: Eye) -> (Vec3, Vec3) {
        let dir = direction(lon, lat);
        let side = Vec3::new(lon.cos(), 0.0, lon.sin());
        let origin = eye.sign() * self.pole_fade(lat.abs()) * self.eye_radius * side;
        let ray = match self.convergence {
            None => dir,
            Some(c) => (c * dir - origin).normalize(),
        };
        (origin, ray)
    }
}

#[cfg(test)]
mod tests {
    use crate::core::panoramas::projection::tests::angle_diff;
    use crate::core::panoramas::projection::{Camera, Eye, Projection, DEFAULT_POLE_MERGE};
    use glam::Vec3;
    use rand::{Rng, SeedableRng};
    use std::f64::consts::PI;

    #[test]
    fn the_sphere_inverse_takes_pixels_back_to_points() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(12);
        for convergence in [None, Some(2.0)] {
            let proj = Projection { convergence, ..Projection::equirect(2048) };
            assert_eq!((proj.kind().name(), proj.size()), ("equirect", [2048, 1024]));
            for _ in 0..2000 {
                let pixel = [rng.random_range(0.0..2048.0f32), rng.random_range(1.0..1023.0f32)];
                let depth = rng.random_range(0.2..30.0f32);
                for eye in Eye::BOTH {
                    let p = proj.unproject_pixel(pixel, depth, eye);
                    let (again, d) = proj.project_pixel(p, eye).unwrap();
                    let (_, lat) = proj.pixel_to_screen(pixel[0], pixel[1]);
                    let dx = proj.wrapped_dx(again[0], pixel[0]) * lat.cos().max(0.01);
                    assert!(dx < 2e-2 && (again[1] - pixel[1]).abs() < 2e-2, "{eye:?} {pixel:?} → {p} → {again:?}");
                    assert!((d - depth).abs() < 1e-4 * depth, "depth {d} vs {depth}");
                }
            }
        }
    }

    /// Cycles' spherical stereo ray of the pixel at (lon, lat), in f64, written from Cycles'
    /// kernel (`spherical_stereo_position` / `_direction`), not from our inverse: origin
    /// side·offset with side = normalize(D × up), offset ±d_e faded with the altitude of D, and
    /// with convergence distance c the direction normalize(c·D − origin).
    fn cycles_ray(
        lon: f64,
        lat: f64,
        side_sign: f64,
        de: f64,
        c: Option<f64>,
        pole: Option<(f64, f64)>,
    ) -> ([f64; 3], [f64; 3]) {
        let d = [lat.cos() * lon.sin(), lat.sin(), -lat.cos() * lon.cos()];
        let up = [0.0, 1.0, 0.0];
        let cross = [d[1] * up[2] - d[2] * up[1], d[2] * up[0] - d[0] * up[2], d[0] * up[1] - d[1] * up[0]];
        let n = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
        let side = cross.map(|x| x / n);
        let mut offset = side_sign * de;
        if let Some((from, to)) = pole {
            let altitude = d[1].asin().abs();
            if altitude > to {
                offset = 0.0;
            } else if altitude > from {
                offset *= (PI / 2.0 * (altitude - from) / (to - from)).cos();
            }
        }
        let origin = side.map(|x| x * offset);
        let dir = match c {
            None => d,
            Some(c) => {
                let v = [c * d[0] - origin[0], c * d[1] - origin[1], c * d[2] - origin[2]];
                let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                v.map(|x| x / n)
            }
        };
        (origin, dir)
    }

    /// The pixel whose Cycles ray passes through p, by Gauss–Newton on the ray's miss distance
    /// (numerical Jacobian), from the direction of p. Returns (lon, lat, distance along the ray)
    /// or None if it does not converge in front of the eye.
    fn brute_force_sphere(
        p: [f64; 3],
        side_sign: f64,
        de: f64,
        c: Option<f64>,
        pole: Option<(f64, f64)>,
    ) -> Option<(f64, f64, f64)> {
        let miss = |x: [f64; 2]| -> ([f64; 3], f64) {
            let (o, dir) = cycles_ray(x[0], x[1], side_sign, de, c, pole);
            let rel = [p[0] - o[0], p[1] - o[1], p[2] - o[2]];
            let t = rel[0] * dir[0] + rel[1] * dir[1] + rel[2] * dir[2];
            ([rel[0] - t * dir[0], rel[1] - t * dir[1], rel[2] - t * dir[2]], t)
        };
        let r = (p[0] * p[0] + p[2] * p[2]).sqrt();
        let mut x = [p[0].atan2(-p[2]), p[1].atan2(r)];
        for _ in 0..200 {
            let (w, _) = miss(x);
            let h = 1e-7;
            let j: Vec<[f64; 3]> = (0..2)
                .map(|k| {
                    let mut xh = x;
                    xh[k] += h;
                    let (wh, _) = miss(xh);
                    [(wh[0] - w[0]) / h, (wh[1] - w[1]) / h, (wh[2] - w[2]) / h]
                })
                .collect();
            let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            let (a, b, cc) = (dot(&j[0], &j[0]), dot(&j[0], &j[1]), dot(&j[1], &j[1]));
            let (g0, g1) = (dot(&j[0], &w), dot(&j[1], &w));
            let det = a * cc - b * b;
            if det.abs() < 1e-300 {
                return None;
            }
            let step = [(cc * g0 - b * g1) / det, (a * g1 - b * g0) / det];
            // Damped, and kept within the sphere's latitudes.
            let scale = 1f64.min(0.2 / step[0].abs().max(step[1].abs()).max(1e-300));
            x = [x[0] - scale * step[0], (x[1] - scale * step[1]).clamp(-PI / 2.0 + 1e-12, PI / 2.0 - 1e-12)];
            if step[0].abs().max(step[1].abs()) < 1e-13 {
                break;
            }
        }
        let (w, t) = miss(x);
        let distance = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
        (distance < 1e-9 * (1.0 + t.abs()) && t > 0.0).then_some((x[0], x[1], t))
    }

    #[test]
    fn the_sphere_matches_cycles_rays_for_both_eyes_every_convergence_and_pole_merge() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(14);
        let mut compared = 0;
        for convergence in [None, Some(1.0f32), Some(3.0)] {
            for pole_merge in [None, Some(DEFAULT_POLE_MERGE), Some((45.0, 80.0))] {
                let proj = Projection { convergence, pole_merge, ..Projection::equirect(4096) };
                let px_per_rad = proj.pixels_per_radian() as f64;
                for _ in 0..1500 {
                    // Directions all over the sphere, 0.1–50 m away (some inside the eye circle).
                    let (a, b): (f64, f64) = (rng.random_range(-1.0..1.0), rng.random_range(-PI..PI));
                    let dist: f64 = 10f64.powf(rng.random_range(-1.0..1.7));
                    let h = (1.0 - a * a).sqrt();
                    let p = [dist * h * b.sin(), dist * a, -dist * h * b.cos()];
                    let pf = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
                    for eye in Eye::BOTH {
                        let pole = pole_merge.map(|(f, t)| ((f as f64).to_radians(), (t as f64).to_radians()));
                        let want = brute_force_sphere(p, eye.sign() as f64, 0.032, convergence.map(|c| c as f64), pole);
                        let got = proj.project(pf, eye);
                        let (Some((lon, lat, t)), Some(q)) = (want, got) else {
                            // Only points an eye cannot see (or that graze the eye circle) may
                            // lack one of the two.
                            let r = (p[0] * p[0] + p[2] * p[2]).sqrt();
                            assert!(r < 0.05, "{convergence:?} {pole_merge:?} {eye:?} {p:?}: brute force {want:?}, projection {got:?}");
                            continue;
                        };
                        let dlon = angle_diff(q.u as f64, lon) * px_per_rad * lat.cos().max(1e-3);
                        let dlat = (q.v as f64 - lat).abs() * px_per_rad;
                        // Longitude compared as the distance it makes on the sphere (columns
                        // shrink towards the poles), in pixels of the equator.
                        assert!(
                            dlon < 1e-3 && dlat < 1e-3,
                            "{convergence:?} {pole_merge:?} {eye:?} p={p:?}: off by {dlon}, {dlat} px"
                        );
                        assert!((q.depth as f64 - t).abs() < 1e-5 * (1.0 + t), "depth {} vs {t}", q.depth);
                        compared += 1;
                    }
                }
            }
        }
        assert!(compared > 20_000, "{compared} points compared");
    }

    /// VR180: the same rays, drawn on the front half's image (x = (λ/π + ½)·W, y = (½ − φ/π)·H,
    /// written here from the format, not from `to_pixel`); points behind fall outside the image;
    /// the inverse takes pixels back to points.
    #[test]
    fn vr180_draws_the_spheres_rays_on_the_front_half() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(18);
        let proj = Projection::vr180(2048);
        assert_eq!((proj.kind().name(), proj.size()), ("vr180", [2048, 2048]));
        let (w, h) = (2048.0, 2048.0);
        let (mut inside, mut behind) = (0, 0);
        for _ in 0..3000 {
            let (a, b): (f64, f64) = (rng.random_range(-1.0..1.0), rng.random_range(-PI..PI));
            let dist: f64 = 10f64.powf(rng.random_range(-0.5..1.5));
            let hz = (1.0 - a * a).sqrt();
            let p = [dist * hz * b.sin(), dist * a, -dist * hz * b.cos()];
            let pf = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
            for eye in Eye::BOTH {
                let pole = Some(DEFAULT_POLE_MERGE).map(|(f, t)| ((f as f64).to_radians(), (t as f64).to_radians()));
                let (Some((lon, lat, t)), Some((q, depth))) =
                    (brute_force_sphere(p, eye.sign() as f64, 0.032, None, pole), proj.project_pixel(pf, eye))
                else {
                    let r = (p[0] * p[0] + p[2] * p[2]).sqrt();
                    assert!(r < 0.05, "{eye:?} {p:?}");
                    continue;
                };
                let x = (lon / PI + 0.5) * w;
                let y = (0.5 - lat / PI) * h;
                if lon.abs() > PI / 2.0 + 1e-3 {
                    assert!(q[0] < 0.0 || q[0] > w as f32, "{eye:?} {p:?} behind, drawn at {q:?}");
                    behind += 1;
                    continue;
                }
                let dx = (q[0] as f64 - x).abs() * lat.cos().max(1e-3);
                assert!(dx < 1e-3 && (q[1] as f64 - y).abs() < 1e-3, "{eye:?} {p:?}: {q:?} vs ({x}, {y})");
                assert!((depth as f64 - t).abs() < 1e-5 * (1.0 + t));
                inside += 1;
                // The inverse.
                let back = proj.unproject_pixel(q, depth, eye);
                assert!((back - pf).length() < 1e-4 * (1.0 + dist as f32), "{p:?} → {q:?} → {back}");
            }
        }
        assert!(inside > 2500 && behind > 2500, "{inside} in front, {behind} behind");
    }

    #[test]
    fn on_the_sphere_the_right_eye_stands_right_and_converging_rays_cross_at_the_convergence_sphere() {
        let ahead = |d: f32, proj: &Projection| {
            let p = Vec3::new(0.0, 0.0, -d);
            proj.project(p, Eye::Right).unwrap().u - proj.project(p, Eye::Left).unwrap().u
        };
        // Parallel rays: the right eye, right of the centre, sees a point ahead to its left.
        let parallel = Projection::equirect(1024);
        assert!(ahead(2.0, &parallel) < 0.0 && ahead(50.0, &parallel) < 0.0);
        assert!(ahead(2.0, &parallel) < ahead(50.0, &parallel));
        // Converging on 2 m: no disparity there, uncrossed (as the cylinder's screen) beyond.
        let converging = Projection { convergence: Some(2.0), ..parallel };
        assert!(ahead(2.0, &converging).abs() < 1e-6);
        assert!(ahead(10.0, &converging) > 0.0 && ahead(1.0, &converging) < 0.0);
        // The pole merge: straight above, both eyes see the same pixel.
        let up = Vec3::new(0.0, 3.0, -0.01);
        let [l, r] = Eye::BOTH.map(|e| parallel.project(up, e).unwrap());
        assert!((l.u - r.u).abs() < 1e-6 && (l.v - r.v).abs() < 1e-6);
        // Without it, the axis above is inside the eye circle: no eye sees it.
        let off = Projection { pole_merge: None, ..parallel };
        assert!(off.project(up, Eye::Left).is_none());
    }
}
