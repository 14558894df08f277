//! The `trace` stage, CPU twin of `shaders/trace.wgsl`: ray tracing (seed 000), a primary ray
//! per sample of each pixel (`--samples`, the pixel's centre for one) and eye from its eye point ([`pixel_ray`]: the cylinder's exact vertical
//! model, or the sphere), the closest hit through the scene's BVH ([`SceneBvh`]), shaded with
//! the rasterizer's materials and headlight, or a point light with shadow rays; mirror and
//! refraction rays to `reflect_max` bounces, depth first. The same traversal as the WGSL (nearer
//! child first, farther on a stack), so that ties resolve alike; the WGSL queues a hit's shadow
//! ray with the light it brings, the twin traces it at once (the same sum).

use std::cell::Cell;

use glam::{Mat4, Vec2, Vec3, Vec4};

use crate::core::detail::visual_field::Gaze;
use crate::core::panoramas::projection::{Eye, Projection};
use crate::core::scenes::bvh::{BvhNode, SceneBvh, OBJECT_LEAF};
use crate::core::scenes::scene::{unpack_tangent, SceneVertex};
use crate::core::shading::color::srgb_to_linear;
use crate::core::shading::light::tonemap;
use crate::core::shading::light::LightKind;
use crate::core::shading::material::AlphaMode;
use crate::core::shading::sampling::sample_position;
use crate::core::shading::texture::MaterialTable;
use crate::cpu::fragment::{
    display_bytes, env_direction, env_level, env_st, light_at, light_term, pbr_radiance, pixel_error, pixel_ray,
    pixel_spread, shade_linear, shading_normal, surface_color, surface_maps, Surface,
};
use crate::cpu::raster::RasterImage;
use crate::encoding::constants::{MAX_SHADOWED_LIGHTS, TRACE_PENDING, TRACE_STACK};
use crate::encoding::types::TraceParams;

/// The closest hit kept along a ray: distance, triangle, barycentrics of corners 1 and 2, and
/// whether the ray meets the triangle's front (counter-clockwise) face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub triangle: u32,
    pub b1: f32,
    pub b2: f32,
    pub front: bool,
}

/// The entry distance of the ray into a node's box (clamped at 0), or None if it misses it or
/// enters beyond `limit` (`enter_box`).
fn enter_box(n: &BvhNode, origin: Vec3, inv: Vec3, limit: f32) -> Option<f32> {
    let t1 = (Vec3::from(n.min) - origin) * inv;
    let t2 = (Vec3::from(n.max) - origin) * inv;
    let near = t1.min(t2).max_element().max(0.0);
    let far = t1.max(t2).min_element().min(limit);
    (near <= far).then_some(near)
}

/// A ray to trace (scene frame): origin, unit direction, the distance it ends at, its visual
/// level (eq. 8; 1 without LOD) and its cone (width at the origin, growth per metre).
#[derive(Clone, Copy, Debug)]
pub struct TracedRay {
    pub origin: Vec3,
    pub dir: Vec3,
    pub limit: f32,
    pub level: f32,
    pub cone: Vec2,
}

/// What rays are traced against: the scene's BVH (with its triangles) and vertices, and the
/// share of an object's triangles that eq. 10 gives a ray of level 0 (N_min / N_max).
#[derive(Clone, Copy)]
pub struct TracedScene<'a> {
    pub bvh: &'a SceneBvh,
    pub vertices: &'a [SceneVertex],
    pub min_share: f32,
}

/// The closest hit along the ray (scene frame), nearer than `limit`, that `keeps` accepts
/// (given the ray's direction and its cone's width there; `cone`: width at the origin, growth
/// per metre) (`closest_hit`): binary BVH,
/// nearer child first (the farther kept with its entry distance, and skipped when popped if the
/// best hit is nearer), Möller–Trumbore per triangle; at an object, the walk goes on in the
/// level of its chain that the ray's visual `level` picks (eq. 10, [`SceneBvh::pick_level`]).
/// Triangles are numbered in `bvh.indices`.
pub fn closest_hit(
    scene: &TracedScene,
    ray: &TracedRay,
    keeps: &dyn Fn(u32, f32, f32, bool, Vec3, f32) -> bool,
    tests: &Cell<u64>,
) -> Option<Hit> {
    let TracedRay { origin, dir, limit, level, cone } = *ray;
    let TracedScene { bvh, vertices, min_share } = *scene;
    let indices = &bvh.indices;
    let mut best: Option<Hit> = None;
    let best_t = |b: &Option<Hit>| b.map_or(limit, |h| h.t);
    let tiny = 1e-20;
    let safe = Vec3::select(dir.abs().cmplt(Vec3::splat(tiny)), Vec3::splat(tiny).copysign(dir), dir);
    let inv = Vec3::ONE / safe;
    // Rays that meet every object's original start at the tree over all of them.
    let mut node = if level > bvh.original_level(min_share) { bvh.original_root as usize } else { 0 };
    enter_box(&bvh.nodes[node], origin, inv, limit)?;
    let position = |tri: u32, k: u32| Vec3::from(vertices[indices[(3 * tri + k) as usize] as usize].position);
    // Nodes still to visit, with the distance where the ray enters their box.
    let mut stack: Vec<(usize, f32)> = Vec::with_capacity(TRACE_STACK as usize);
    loop {
        let n = &bvh.nodes[node];
        let mut descend = false;
        if n.count & OBJECT_LEAF != 0 {
            let levels = &bvh.levels[n.first as usize..(n.first + (n.count & !OBJECT_LEAF)) as usize];
            node = levels[SceneBvh::pick_level(levels, level, min_share)].root as usize;
            continue;
        }
        if n.count > 0 {
            tests.set(tests.get() + n.count as u64);
            for k in 0..n.count {
                let tri = n.first + k;
                let v0 = position(tri, 0);
                let (e1, e2) = (position(tri, 1) - v0, position(tri, 2) - v0);
                let p = dir.cross(e2);
                let det = e1.dot(p);
                if det.abs() < 1e-12 {
                    continue;
                }
                let inv_det = 1.0 / det;
                let s = origin - v0;
                let b1 = s.dot(p) * inv_det;
                let q = s.cross(e1);
                let b2 = dir.dot(q) * inv_det;
                let t = e2.dot(q) * inv_det;
                if b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 || !(t > 0.0) || t >= best_t(&best) {
                    continue;
                }
                if keeps(tri, b1, b2, det > 0.0, dir, cone.x + cone.y * t) {
                    best = Some(Hit { t, triangle: tri, b1, b2, front: det > 0.0 });
                }
            }
        } else {
            let (a, b) = (n.first as usize, n.first as usize + 1);
            let limit = best_t(&best);
            match (enter_box(&bvh.nodes[a], origin, inv, limit), enter_box(&bvh.nodes[b], origin, inv, limit)) {
                (Some(ta), Some(tb)) => {
                    let (near, far) = if ta <= tb { (a, b) } else { (b, a) };
                    if stack.len() < TRACE_STACK as usize {
                        stack.push((far, ta.max(tb)));
                    }
                    node = near;
                    descend = true;
                }
                (Some(_), None) => (node, descend) = (a, true),
                (None, Some(_)) => (node, descend) = (b, true),
                (None, None) => {}
            }
        }
        if descend {
            continue;
        }
        // The latest pending node the ray enters before the best hit so far.
        match std::iter::from_fn(|| stack.pop()).find(|&(_, t)| t < best_t(&best)) {
            Some((next, _)) => node = next,
            None => break,
        }
    }
    best
}

/// What a hit shows (`shade_hit`): its own light (weighted 1 − mirror − transmission, sRGB-free
/// linear), its optics, the tint of mirrored light, the normal facing the ray (scene frame).
struct Shaded {
    color: Vec3,
    mirror: f32,
    transmission: f32,
    tint: Vec3,
    normal: Vec3,
    ior: f32,
    front: bool,
}

/// The refracted direction (Snell's law; `n` facing the incoming ray, eta = n₁/n₂), or the
/// mirrored one under total internal reflection (`refract_or_reflect`).
pub fn refract_or_reflect(d: Vec3, n: Vec3, eta: f32) -> Vec3 {
    let cos_i = -d.dot(n);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return d - 2.0 * d.dot(n) * n;
    }
    (eta * d + (eta * cos_i - k.sqrt()) * n).normalize()
}

/// What the trace stage makes: both eyes' images (left, right), and the rays traced (primary,
/// mirror, refraction, shadow) and ray–triangle tests made.
pub struct TraceOutput {
    pub images: [RasterImage; 2],
    pub rays: u64,
    pub triangle_tests: u64,
}

/// The trace stage on the CPU.
pub fn trace(params: &TraceParams, vertices: &[SceneVertex], bvh: &SceneBvh, table: &MaterialTable) -> TraceOutput {
    let tracer = Tracer::new(params, vertices, bvh, table);
    let projection = &tracer.projection;
    let [r, g, b, _] = params.background;
    let images = Eye::BOTH.map(|eye| {
        // The image's background is given in display values, as `RasterImage::new` takes it.
        // This draw's image: a tile of the frame, or the frame.
        let [w, h] = projection.image_size();
        let mut img = RasterImage::new(w, h, [r, g, b]);
        for y in 0..h {
            for x in 0..w {
                tracer.trace_pixel(eye, x, y, &mut img);
            }
        }
        img
    });
    TraceOutput { images, rays: tracer.rays.get(), triangle_tests: tracer.tests.get() }
}

/// A ray's choice of the triangles it meets (`keeps` of [`closest_hit`]).
type Keeps<'k> = &'k dyn Fn(u32, f32, f32, bool, Vec3, f32) -> bool;

/// What tracing a frame reads (the scene, its tree and material table, the frame's parameters
/// and what follows from them) and what it counts (rays traced, ray–triangle tests).
struct Tracer<'a> {
    params: &'a TraceParams,
    vertices: &'a [SceneVertex],
    traced: TracedScene<'a>,
    table: &'a MaterialTable,
    projection: Projection,
    to_scene: Mat4,
    to_view: glam::Mat3,
    to_scene_rotation: glam::Mat3,
    viewer: Vec3,
    /// The background, linear.
    background: Vec3,
    /// `--light`: a point light (scene frame) instead of the scene's lights.
    light: Option<Vec3>,
    gaze: Option<Gaze>,
    /// Whether the environment lights the rays (`environment_lit` in trace.wgsl).
    environment_lit: bool,
    rays: Cell<u64>,
    tests: Cell<u64>,
}

impl<'a> Tracer<'a> {
    fn new(params: &'a TraceParams, vertices: &'a [SceneVertex], bvh: &'a SceneBvh, table: &'a MaterialTable) -> Self {
        let to_scene = Mat4::from_cols_array_2d(&params.to_scene);
        let [r, g, b, _] = params.background;
        let light = (params.light[3] > 0.0).then(|| Vec3::new(params.light[0], params.light[1], params.light[2]));
        Tracer {
            params,
            vertices,
            traced: TracedScene { bvh, vertices, min_share: params.lod_min_share },
            table,
            projection: Projection::from(&params.projection),
            to_scene,
            to_view: glam::Mat3::from_mat4(to_scene).transpose(),
            to_scene_rotation: glam::Mat3::from_mat4(to_scene),
            viewer: to_scene.w_axis.truncate(),
            background: Vec3::new(r, g, b).map(srgb_to_linear),
            light,
            gaze: (params.gaze_forward[3] > 0.0).then(|| Gaze {
                forward: Vec4::from(params.gaze_forward).truncate(),
                right: Vec4::from(params.gaze_right).truncate(),
                up: Vec4::from(params.gaze_up).truncate(),
            }),
            environment_lit: table.lighting.pbr != 0 && table.lighting.environment != 0 && light.is_none(),
            rays: Cell::new(0),
            tests: Cell::new(0),
        }
    }

    fn corners(&self, tri: u32) -> [&'a SceneVertex; 3] {
        let indices = &self.traced.bvh.indices;
        [0, 1, 2].map(|k| &self.vertices[indices[(3 * tri + k) as usize] as usize])
    }

    fn material(&self, tri: u32) -> &'a crate::core::shading::material::Material {
        let materials = &self.table.materials;
        &materials[(self.corners(tri)[0].material as usize).min(materials.len() - 1)]
    }

    /// The footprint of a ray cone `width` wide meeting `tri` along `dir` (`texture_footprint`):
    /// the ellipse it draws on the triangle's plane as its two axes in texture units, along the
    /// ray's trace (width / |cos incidence|, at most 20×) and across it (width).
    fn footprint(&self, tri: u32, dir: Vec3, width: f32) -> (Vec2, Vec2) {
        let [a, b, c] = self.corners(tri);
        let (e1, e2) =
            (Vec3::from(b.position) - Vec3::from(a.position), Vec3::from(c.position) - Vec3::from(a.position));
        let n = e1.cross(e2);
        let world = n.length().max(1e-30);
        let normal = n / world;
        let cos_i = normal.dot(dir).abs().max(0.05);
        let mut along = dir - normal * normal.dot(dir);
        if along.dot(along) < 1e-12 {
            along = e1;
        }
        let along = along.normalize();
        let (major, minor) = (along * (width / cos_i), normal.cross(along) * width);
        // w = s·e1 + t·e2 in the plane: s = w·(e2 × n̂)/|n|, t = w·(n̂ × e1)/|n|.
        let (to_s, to_t) = (e2.cross(normal) / world, normal.cross(e1) / world);
        let (d1, d2) = (Vec2::from(b.uv) - Vec2::from(a.uv), Vec2::from(c.uv) - Vec2::from(a.uv));
        let to_uv = |w: Vec3| w.dot(to_s) * d1 + w.dot(to_t) * d2;
        (to_uv(major), to_uv(minor))
    }

    /// The surface at barycentrics (b1, b2) of `tri`, its texture footprint `f` (the ellipse's
    /// axes).
    fn surface(&self, tri: u32, b1: f32, b2: f32, front: bool, frag_xy: Vec2, f: (Vec2, Vec2)) -> Surface {
        let [a, b, c] = self.corners(tri);
        let b0 = 1.0 - b1 - b2;
        let mix4 = |x: [f32; 4], y: [f32; 4], z: [f32; 4]| b0 * Vec4::from(x) + b1 * Vec4::from(y) + b2 * Vec4::from(z);
        let mix2 = |x: [f32; 2], y: [f32; 2], z: [f32; 2]| b0 * Vec2::from(x) + b1 * Vec2::from(y) + b2 * Vec2::from(z);
        Surface {
            material: a.material,
            color: mix4(a.color, b.color, c.color),
            uv: mix2(a.uv, b.uv, c.uv),
            duv_dx: f.0,
            duv_dy: f.1,
            frag_xy,
            front_facing: front,
            tangent: b0 * unpack_tangent(a.tangent) + b1 * unpack_tangent(b.tangent) + b2 * unpack_tangent(c.tangent),
        }
    }

    /// Whether a ray of the pixel at `frag_xy` stops at this hit of `tri` (opaque and facing it,
    /// or a masked or blended surface that shows there).
    #[allow(clippy::too_many_arguments)]
    fn keeps(&self, frag_xy: Vec2, tri: u32, b1: f32, b2: f32, front: bool, dir: Vec3, width: f32) -> bool {
        let m = self.material(tri);
        if m.alpha_mode == AlphaMode::Opaque as u32 {
            return front || m.double_sided != 0;
        }
        let f = self.footprint(tri, dir, width);
        surface_color(self.table, &self.surface(tri, b1, b2, front, frag_xy, f)).is_some()
    }

    /// Traces a shadow ray; whether it meets nothing.
    fn unshadowed(&self, origin: Vec3, dir: Vec3, limit: f32, level: f32, width: f32, keeps: Keeps) -> bool {
        self.rays.set(self.rays.get() + 1);
        let ray = TracedRay { origin, dir, limit, level, cone: Vec2::new(width, 0.0) };
        closest_hit(&self.traced, &ray, keeps, &self.tests).is_none()
    }

    /// What a hit shows (`shade_hit` in trace.wgsl).
    #[allow(clippy::too_many_arguments)]
    fn shade_hit(
        &self,
        hit: &Hit,
        dir: Vec3,
        p: Vec3,
        view_position: Vec3,
        frag_xy: Vec2,
        level: f32,
        width: f32,
        keeps: Keeps,
    ) -> Shaded {
        let [a, b, c] = self.corners(hit.triangle);
        let b0 = 1.0 - hit.b1 - hit.b2;
        let mut n = b0 * Vec3::from(a.normal) + hit.b1 * Vec3::from(b.normal) + hit.b2 * Vec3::from(c.normal);
        if n.length_squared() < 1e-12 {
            let p = |v: &SceneVertex| Vec3::from(v.position);
            n = (p(b) - p(a)).cross(p(c) - p(a));
        }
        let n = n.normalize();
        let f = self.footprint(hit.triangle, dir, width);
        let hit_surface = self.surface(hit.triangle, hit.b1, hit.b2, hit.front, frag_xy, f);
        let color = surface_color(self.table, &hit_surface).expect("a kept hit has a colour");
        let m = self.material(hit.triangle);
        let own = (1.0 - m.mirror - m.transmission).max(0.0);
        let facing = if n.dot(dir) > 0.0 { -n } else { n };
        let lit = match self.light {
            // The glTF BRDF under the scene's lights, seen along the ray (tone mapped once the
            // pixel's light is summed).
            None if self.table.lighting.pbr != 0 => {
                let shading = Shading { n, facing, color, own, level, width };
                self.shade_pbr(hit, &hit_surface, dir, p, view_position, &shading, keeps)
            }
            None => shade_linear(self.params.ambient, view_position, self.to_view * n, color) * own,
            Some(light) => {
                // Lambert towards the light, one-sided; the direct part only if the shadow ray
                // (traced where there is direct light to lose) meets nothing.
                let to_light = light - p;
                let dist = to_light.length();
                let l = to_light / dist.max(1e-20);
                let base = color.truncate().clamp(Vec3::ZERO, Vec3::ONE) * own;
                let direct = base * (1.0 - self.params.ambient) * facing.dot(l).max(0.0);
                let mut lit = base * self.params.ambient;
                let offset = 1e-4 * p.length().max(1.0);
                if direct.max_element() > 0.0
                    && self.unshadowed(p + offset * facing, l, dist - offset, level, width, keeps)
                {
                    lit += direct;
                }
                lit
            }
        };
        Shaded {
            color: lit,
            mirror: m.mirror,
            transmission: m.transmission,
            tint: color.truncate(),
            normal: facing,
            ior: m.ior,
            front: hit.front,
        }
    }

    /// The glTF BRDF at a hit under the scene's lights: the first `MAX_SHADOWED_LIGHTS` behind
    /// their shadow rays, the others directly; the file's tangents, else the frame from the
    /// triangle's edges.
    #[allow(clippy::too_many_arguments)]
    fn shade_pbr(
        &self,
        hit: &Hit,
        hit_surface: &Surface,
        dir: Vec3,
        p: Vec3,
        view_position: Vec3,
        shading: &Shading,
        keeps: Keeps,
    ) -> Vec3 {
        let (table, to_view) = (self.table, self.to_view);
        let Shading { n, facing, color, own, level, width } = *shading;
        let [a, b, c] = self.corners(hit.triangle);
        let (pa, pb, pc) = (Vec3::from(a.position), Vec3::from(b.position), Vec3::from(c.position));
        let (ua, ub, uc) = (Vec2::from(a.uv), Vec2::from(b.uv), Vec2::from(c.uv));
        let maps = surface_maps(
            table,
            a.material,
            hit_surface.uv,
            hit_surface.duv_dx,
            hit_surface.duv_dy,
            [to_view * (pb - pa), to_view * (pc - pa)],
            [ub - ua, uc - ua],
            (to_view * hit_surface.tangent.truncate()).extend(hit_surface.tangent.w),
        );
        let v = -(to_view * dir);
        let shadowed = if table.lighting.shadows != 0 {
            (table.lighting.count as usize).min(MAX_SHADOWED_LIGHTS as usize)
        } else {
            0
        };
        let mut lit =
            pbr_radiance(table, self.params.ambient, v, view_position, to_view * n, color, &maps, shadowed) * own;
        let shading_n = shading_normal(to_view * n, v, &maps);
        let base = color.truncate().max(Vec3::ZERO);
        let offset = 1e-4 * p.length().max(1.0);
        for light in &table.lights[..shadowed] {
            let term = light_term(light, shading_n, v, view_position, base, &maps) * own;
            if term.max_element() > 0.0 {
                let limit = if light.kind == LightKind::Directional as u32 {
                    FAR
                } else {
                    (Vec3::from(light.position) - view_position).length() - offset
                };
                let (l, _) = light_at(light, view_position);
                let towards = self.to_scene_rotation * l;
                if self.unshadowed(p + offset * facing, towards, limit, level, width, keeps) {
                    lit += term;
                }
            }
        }
        lit
    }

    /// Traces the pixel (x, y) of `eye` into `img` as the WGSL: `samples` rays through the
    /// pixel's sample positions ([`sample_position`]; one: the centre), the average of their
    /// tone-mapped colours in linear light, a pixel all plain background exactly the background;
    /// the error, object and distance outputs from the centre's ray.
    fn trace_pixel(&self, eye: Eye, x: u32, y: u32, img: &mut RasterImage) {
        let n = self.params.samples.max(1);
        let corner = Vec2::new(x as f32, y as f32) + self.projection.tile_origin();
        let i = (y * self.projection.image_size()[0] + x) as usize;
        if n > 1 {
            // The centre's ray for the outputs alone (one sample is the centre's itself).
            self.trace_sample(eye, corner + 0.5, Some((i, &mut *img)), false);
        }
        let (mut sum, mut plain) = (Vec3::ZERO, 0);
        for k in 0..n {
            let (color, is_plain) =
                self.trace_sample(eye, corner + sample_position(n, k), (n == 1).then_some((i, &mut *img)), true);
            sum += color;
            plain += is_plain as u32;
        }
        if plain < n {
            img.rgba[4 * i..4 * i + 4].copy_from_slice(&display_bytes(sum / n as f32));
        }
    }

    /// The primary ray through `frag_xy` and its visual level and bounces (seed 000's level of
    /// detail: None outside the visual field, else level × Reflect_max bounces, eq. 9, rounded;
    /// its rays meet each object at the level of detail eq. 10 gives, level 1 the original),
    /// in the viewer's frame and the scene's.
    fn primary(&self, eye: Eye, frag_xy: Vec2) -> Option<(Vec3, Vec3, TracedRay, u32)> {
        let params = self.params;
        if !self.projection.shows_pixel(frag_xy.x, frag_xy.y) {
            return None; // outside the fisheye's circle
        }
        let (origin_v, dir_v) = pixel_ray(&self.projection, eye, frag_xy);
        let (level, reflect_max) = match self.gaze {
            None => (1.0, params.reflect_max),
            Some(g) => {
                let level = g.position(dir_v).level();
                if level <= 0.0 {
                    return None;
                }
                (level, (level * params.reflect_max as f32 + 0.5).floor() as u32)
            }
        };
        // The pixel's angular size: the cone's growth per metre.
        let spread = pixel_spread(&self.projection, frag_xy);
        let ray = TracedRay {
            origin: self.to_scene.transform_point3(origin_v),
            dir: self.to_scene.transform_vector3(dir_v),
            limit: FAR,
            level,
            cone: Vec2::new(0.0, spread),
        };
        Some((origin_v, dir_v, ray, reflect_max))
    }

    /// The outputs of a primary ray's hit at `view_position`.
    fn write_primary(&self, eye: Eye, frag_xy: Vec2, view_position: Vec3, hit: &Hit, i: usize, img: &mut RasterImage) {
        img.error[i] = pixel_error(&self.projection, eye, view_position, frag_xy, self.params.error_angle != 0);
        img.object[i] = self.corners(hit.triangle)[0].object + 1;
        img.distance[i] = hit.t;
        img.depth[i] = hit.t;
    }

    /// One sample: its primary ray through `frag_xy`, then its mirror and refraction rays depth
    /// first (as the WGSL); its tone-mapped linear colour and whether that is the plain
    /// background. With `centre` (pixel index and image) the primary hit's outputs are written;
    /// without `shade` nothing more is traced (the centre's ray beside several samples).
    fn trace_sample(
        &self,
        eye: Eye,
        frag_xy: Vec2,
        centre: Option<(usize, &mut RasterImage)>,
        shade: bool,
    ) -> (Vec3, bool) {
        let table = self.table;
        let keeps = |tri, b1, b2, front, dir, width| self.keeps(frag_xy, tri, b1, b2, front, dir, width);
        let Some((origin_v, dir_v, primary, reflect_max)) = self.primary(eye, frag_xy) else {
            return (self.background, true);
        };
        self.rays.set(self.rays.get() + 1);
        let Some(hit) = closest_hit(&self.traced, &primary, &keeps, &self.tests) else {
            if self.environment_lit && table.lighting.env_background != 0 {
                return (tonemap(env_level(table, 0, env_st(env_direction(table, dir_v))), &table.lighting), false);
            }
            return (self.background, true);
        };
        if let Some((i, img)) = centre {
            self.write_primary(eye, frag_xy, origin_v + hit.t * dir_v, &hit, i, img);
        }
        if !shade {
            return (Vec3::ZERO, false);
        }
        let (level, spread) = (primary.level, primary.cone.y);
        let color = self.gather(primary.origin, primary.dir, hit, frag_xy, spread, level, reflect_max, &keeps);
        if table.lighting.pbr != 0 && self.light.is_none() {
            return (tonemap(color, &table.lighting), false);
        }
        (color, false)
    }

    /// The light a primary ray gathers from its first hit and the mirror and refraction rays
    /// after it, depth first (as the WGSL): each pending ray is (origin, bounces, direction,
    /// weight, the cone's width at the origin).
    #[allow(clippy::too_many_arguments)]
    fn gather(
        &self,
        origin: Vec3,
        dir: Vec3,
        hit: Hit,
        frag_xy: Vec2,
        spread: f32,
        level: f32,
        reflect_max: u32,
        keeps: Keeps,
    ) -> Vec3 {
        let table = self.table;
        let mut pending: Vec<(Vec3, u32, Vec3, Vec3, f32)> = Vec::with_capacity(TRACE_PENDING as usize);
        let mut color = Vec3::ZERO;
        let (mut current, mut current_hit) = ((origin, 0u32, dir, Vec3::ONE, 0.0f32), Some(hit));
        loop {
            let (o, bounces, d, weight, cone) = current;
            match current_hit {
                // A mirrored or refracted ray leaving the scene brings the environment's light.
                None if self.environment_lit => {
                    color += weight * env_level(table, 0, env_st(env_direction(table, self.to_view * d)))
                }
                None => color += weight * self.background,
                Some(h) => {
                    let p = o + h.t * d;
                    let width = cone + spread * h.t;
                    let s = self.shade_hit(&h, d, p, self.to_view * (p - self.viewer), frag_xy, level, width, keeps);
                    color += weight * s.color;
                    let offset = 1e-4 * p.length().max(1.0);
                    if bounces < reflect_max {
                        if s.mirror > 0.0 && pending.len() < TRACE_PENDING as usize {
                            let r = d - 2.0 * d.dot(s.normal) * s.normal;
                            pending.push((p + offset * s.normal, bounces + 1, r, weight * s.mirror * s.tint, width));
                        }
                        if s.transmission > 0.0 && pending.len() < TRACE_PENDING as usize {
                            let eta = if s.front { 1.0 / s.ior } else { s.ior };
                            let t = refract_or_reflect(d, s.normal, eta);
                            let side = if t.dot(s.normal) < 0.0 { -s.normal } else { s.normal };
                            pending.push((p + offset * side, bounces + 1, t, weight * s.transmission, width));
                        }
                    }
                }
            }
            let Some(next) = pending.pop() else { break };
            current = next;
            self.rays.set(self.rays.get() + 1);
            let ray = TracedRay { origin: next.0, dir: next.2, limit: FAR, level, cone: Vec2::new(next.4, spread) };
            current_hit = closest_hit(&self.traced, &ray, keeps, &self.tests);
        }
        color
    }
}

/// A hit's shading inputs shared by the lighting models: the normal (and facing the ray), the
/// surface colour, the weight of its own light, the ray's level of detail and cone width.
#[derive(Clone, Copy)]
struct Shading {
    n: Vec3,
    facing: Vec3,
    color: Vec4,
    own: f32,
    level: f32,
    width: f32,
}

/// "No hit" distance of a ray (`FAR` in trace.wgsl).
const FAR: f32 = 3.0e38;
