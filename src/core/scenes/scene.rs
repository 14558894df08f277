//! A scene: indexed triangles with per-vertex attributes, in world units (metres after
//! `scale`), plus the named objects they belong to.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec4};

use crate::core::panoramas::projection::Projection;
use crate::core::shading::material::Material;
use crate::core::shading::texture::{MaterialTable, Texture};
use crate::error::{Error, Result};

/// A scene vertex as the stages read it (`SceneVertex` in shaders/shared/scene.wgsl). 64 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SceneVertex {
    pub position: [f32; 3],
    pub material: u32,
    pub normal: [f32; 3],
    /// Index of the scene object the vertex belongs to.
    pub object: u32,
    pub color: [f32; 4],
    pub uv: [f32; 2],
    /// The glTF tangent (xyz, bitangent sign w), packed by [`pack_tangent`]; 0: none (the
    /// normal map's frame then comes from the texture coordinates' derivatives).
    pub tangent: u32,
    /// [`SINGLE_SIDED`]: the vertex's material draws no back faces ([`Scene::mark_sides`]).
    pub flags: u32,
}

/// `SceneVertex::flags`: the material is single-sided (glTF's `doubleSided: false`), so a
/// triangle every eye sees from behind is drawn nowhere and the subdivision skips it.
pub const SINGLE_SIDED: u32 = 1;

/// Where the packed tangent's sign and presence bits are.
const TANGENT_NEGATIVE: u32 = 1 << 30;
const TANGENT_PRESENT: u32 = 1 << 31;

/// A tangent and its bitangent sign (glTF's `TANGENT`: unit xyz, w = ±1) in 32 bits, as
/// `SceneVertex::tangent` and `DrawVertex::tangent` hold it: the direction's octahedral
/// coordinates in 15 bits each (bits 0–14 and 15–29; an angular error below 2e-4 rad), w < 0 in
/// bit 30, bit 31 set. A zero or non-finite direction packs to 0, no tangent (`pack_tangent` in
/// shaders/shared/scene.wgsl).
pub fn pack_tangent(t: glam::Vec4) -> u32 {
    let d = t.truncate();
    let sum = d.x.abs() + d.y.abs() + d.z.abs();
    if !(sum > 0.0 && sum.is_finite()) {
        return 0;
    }
    let (mut ex, mut ey) = (d.x / sum, d.y / sum);
    if d.z < 0.0 {
        let sign = |v: f32| if v >= 0.0 { 1.0 } else { -1.0 };
        (ex, ey) = ((1.0 - ey.abs()) * sign(ex), (1.0 - ex.abs()) * sign(ey));
    }
    let q = |e: f32| ((e.clamp(-1.0, 1.0) * 16383.0 + 0.5).floor() + 16384.0) as u32;
    q(ex) | q(ey) << 15 | if t.w < 0.0 { TANGENT_NEGATIVE } else { 0 } | TANGENT_PRESENT
}

/// The tangent of [`pack_tangent`]: unit xyz and w = ±1, or zero for none.
pub fn unpack_tangent(bits: u32) -> glam::Vec4 {
    if bits & TANGENT_PRESENT == 0 {
        return glam::Vec4::ZERO;
    }
    let e = |b: u32| (b & 0x7fff) as f32 / 16383.0 - 16384.0 / 16383.0;
    let (ex, ey) = (e(bits), e(bits >> 15));
    let mut n = Vec3::new(ex, ey, 1.0 - ex.abs() - ey.abs());
    let t = (-n.z).max(0.0);
    n.x += if n.x >= 0.0 { -t } else { t };
    n.y += if n.y >= 0.0 { -t } else { t };
    n.normalize().extend(if bits & TANGENT_NEGATIVE != 0 { -1.0 } else { 1.0 })
}

/// The most triangles a scene may hold (the subdivision indexes pieces in 32 bits).
pub const MAX_TRIANGLES: usize = u32::MAX as usize / 64;

/// The largest coordinate a scene may have, in its units: squares and sums of squares stay finite
/// in f32 (the projection computes x² + z²), with room for the view transform.
pub const MAX_COORDINATE: f32 = 1e15;

/// A named range of triangles (a glTF mesh instance, an OBJ object, a built-in shape).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Object {
    pub name: String,
    pub first_triangle: u32,
    pub triangle_count: u32,
}

#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub name: String,
    pub vertices: Vec<SceneVertex>,
    /// Three indices per triangle.
    pub indices: Vec<u32>,
    pub objects: Vec<Object>,
    /// Things the loader skipped or guessed, for the user to read.
    pub warnings: Vec<String>,
    /// The file's materials; a vertex's `material` is an index here + 1 (0: the default
    /// material). Base colour factors are already in the vertex colours.
    pub materials: Vec<Material>,
    /// Decoded textures that `materials` refer to.
    pub textures: Vec<Texture>,
    /// Cameras placed in the file (glTF camera nodes), usable as the viewer.
    pub cameras: Vec<Camera>,
    /// Punctual lights placed in the file (glTF `KHR_lights_punctual`).
    pub lights: Vec<crate::core::shading::light::Light>,
    /// Whether the file describes its materials for the glTF BRDF (a glTF file): `--lighting
    /// auto` then lights it so, with the neutral environment where it has no lights.
    pub physically_based: bool,
    /// The environment that lights it (image-based lighting, `--environment`), prepared.
    pub environment: Option<std::sync::Arc<crate::core::shading::environment::PreparedEnvironment>>,
    /// Meshes drawn (glTF mesh instances, OBJ objects/groups, built-in shapes: one per object)
    /// and their primitives.
    pub meshes: usize,
    pub primitives: usize,
    /// What moves (glTF animation, skins, morph targets), where the file has any.
    pub rig: Option<Box<crate::core::scenes::animation::Rig>>,
}

/// A camera placed in a scene file: where it stands and which way it looks (yaw only: the
/// panorama is level).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Camera {
    pub name: String,
    pub position: [f32; 3],
    /// Turn about +y from looking along −z, degrees, positive to the left (as `--yaw`).
    pub yaw_deg: f32,
}

impl Scene {
    pub fn new(name: impl Into<String>) -> Self {
        Scene { name: name.into(), ..Default::default() }
    }

    /// The table of the scene's materials and textures, as the fragment stage reads it, with at
    /// most `max_texels` texels (see [`MaterialTable::build`]).
    pub fn material_table(&self, max_texels: usize) -> MaterialTable {
        let table = MaterialTable::build(&self.materials, &self.textures, max_texels);
        match &self.environment {
            Some(env) => table.with_environment(env),
            None => table,
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Appends a mesh as one object; `indices` refer to `vertices`.
    pub fn add_mesh(&mut self, name: impl Into<String>, vertices: &[SceneVertex], indices: &[u32]) {
        let base = self.vertices.len() as u32;
        let first = self.triangle_count() as u32;
        let object = self.objects.len() as u32;
        self.vertices.extend(vertices.iter().map(|v| SceneVertex { object, ..*v }));
        self.indices.extend(indices.iter().map(|i| i + base));
        self.objects.push(Object {
            name: name.into(),
            first_triangle: first,
            triangle_count: (indices.len() / 3) as u32,
        });
        self.meshes += 1;
        self.primitives += 1;
    }

    /// Merges the objects from index `first` on (consecutive triangle ranges) into one named
    /// object; nothing happens when there are none.
    pub fn merge_objects_from(&mut self, first: usize, name: String) {
        if first >= self.objects.len() {
            return;
        }
        let first_triangle = self.objects[first].first_triangle;
        let triangle_count = self.objects[first..].iter().map(|o| o.triangle_count).sum();
        self.meshes -= self.objects.len() - first - 1;
        self.objects.truncate(first);
        let object = first as u32;
        let range = 3 * first_triangle as usize..3 * (first_triangle + triangle_count) as usize;
        for &i in &self.indices[range] {
            self.vertices[i as usize].object = object;
        }
        self.objects.push(Object { name, first_triangle, triangle_count });
    }

    /// Sets each vertex's [`SINGLE_SIDED`] flag from its material as the drawing stages look it
    /// up (index 0 the default material, an index past the last the last one): set, the
    /// subdivision skips the triangles every eye sees from behind, which are drawn nowhere.
    pub fn mark_sides(&mut self) {
        let single: Vec<bool> =
            std::iter::once(false).chain(self.materials.iter().map(|m| m.double_sided == 0)).collect();
        for v in &mut self.vertices {
            let one_sided = single[(v.material as usize).min(single.len() - 1)];
            v.flags = if one_sided { v.flags | SINGLE_SIDED } else { v.flags & !SINGLE_SIDED };
        }
    }

    /// Checks what the GPU stages rely on: whole triangles, indices in range, finite values.
    /// The error names the problem; callers add the file name.
    pub fn validate(&self) -> Result<()> {
        let err = |m: String| Error::scene(&self.name, m);
        if self.indices.len() % 3 != 0 {
            return Err(err(format!("index count {} is not a multiple of 3", self.indices.len())));
        }
        let n = self.vertices.len();
        if let Some((k, i)) = self.indices.iter().enumerate().find(|(_, &i)| i as usize >= n) {
            return Err(err(format!("triangle {} uses vertex index {i}, but there are only {n} vertices", k / 3)));
        }
        for (k, v) in self.vertices.iter().enumerate() {
            if let Some(c) = v.position.iter().find(|c| c.abs() > MAX_COORDINATE) {
                return Err(err(format!(
                    "vertex {k} lies {c:e} from the origin; twister draws coordinates within ±{MAX_COORDINATE:e} (a wrong unit or scale?)"
                )));
            }
            let attributes: [(&str, &[f32]); 4] =
                [("position", &v.position), ("normal", &v.normal), ("colour", &v.color), ("texture coordinate", &v.uv)];
            if let Some((what, value)) = attributes.iter().find(|(_, x)| !x.iter().all(|c| c.is_finite())) {
                return Err(err(format!("vertex {k} has a NaN or infinite {what} {value:?}")));
            }
        }
        if self.indices.len() / 3 > MAX_TRIANGLES {
            return Err(err(format!(
                "{} triangles is more than twister draws ({MAX_TRIANGLES})",
                self.indices.len() / 3
            )));
        }
        Ok(())
    }
}

/// Bounding sphere (centre, radius) of each object, in scene coordinates.
pub fn object_spheres(scene: &Scene) -> Vec<(Vec3, f32)> {
    scene
        .objects
        .iter()
        .map(|o| {
            let tri = &scene.indices[3 * o.first_triangle as usize..3 * (o.first_triangle + o.triangle_count) as usize];
            let pos = |i: &u32| Vec3::from(scene.vertices[*i as usize].position);
            let (lo, hi) =
                tri.iter().map(pos).fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| (l.min(p), h.max(p)));
            let center = (lo + hi) / 2.0;
            (center, tri.iter().map(|i| (pos(i) - center).length()).fold(0.0, f32::max))
        })
        .collect()
}

/// Area-weighted vertex normals from the faces.
pub fn compute_normals(vertices: &mut [SceneVertex], indices: &[u32]) {
    let mut acc = vec![Vec3::ZERO; vertices.len()];
    for t in indices.chunks_exact(3) {
        let p = [0, 1, 2].map(|k| Vec3::from(vertices[t[k] as usize].position));
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        for &i in t {
            acc[i as usize] += n;
        }
    }
    for (v, n) in vertices.iter_mut().zip(acc) {
        v.normal = n.normalize_or_zero().into();
    }
}

impl Scene {
    /// Axis-aligned bounds of the vertices used by triangles.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.indices.iter().map(|&i| Vec3::from(self.vertices[i as usize].position));
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
    }

    /// Applies an affine transform to positions and normals.
    pub fn transform(&mut self, m: Mat4) {
        if let Some(rig) = self.rig.as_mut() {
            rig.placement = m * rig.placement;
        }
        let normal_matrix = m.inverse().transpose();
        for v in &mut self.vertices {
            v.position = m.transform_point3(Vec3::from(v.position)).into();
            v.normal = normal_matrix.transform_vector3(Vec3::from(v.normal)).normalize_or_zero().into();
        }
        // The file's cameras move with the scene (so `--viewer camera` stands where it did
        // relative to the geometry after `--fit` or `--scale`), and turn with it.
        // Lights move with it; a point or spot light scaled by s lights its scaled surroundings
        // as before when its intensity grows by s² (its light falls as 1/d²).
        let scale2 = m.transform_vector3(Vec3::X).length_squared();
        for light in &mut self.lights {
            *light = light.transformed(m);
            if light.kind != crate::core::shading::light::LightKind::Directional {
                light.color *= scale2;
            }
        }
        for camera in &mut self.cameras {
            camera.position = m.transform_point3(Vec3::from(camera.position)).into();
            let yaw = camera.yaw_deg.to_radians();
            let forward = m.transform_vector3(Vec3::new(-yaw.sin(), 0.0, -yaw.cos()));
            if forward.x != 0.0 || forward.z != 0.0 {
                camera.yaw_deg = (-forward.x).atan2(-forward.z).to_degrees();
            }
        }
    }

    /// `--fit DIST`: moves and scales the scene so that its bounding box stands `distance` m
    /// straight ahead, centred on the eye height, its front face filling the screen height
    /// (v = R_T·y/r at the front).
    pub fn fit(&mut self, distance: f32, projection: &Projection) -> Result<()> {
        let (lo, hi) = self.bounds().ok_or_else(|| Error::setting("fit", "needs a scene with triangles"))?;
        let size = hi - lo;
        if !(size.y > 0.0) || !(distance > projection.eye_radius) || !distance.is_finite() {
            return Err(Error::setting(
                "fit",
                format!("needs a scene with height and a finite distance beyond the eye circle, got {distance}"),
            ));
        }
        // Front face at depth distance − s·dz/2 spans ±k = (s·h/2)/(front depth): the screen's
        // height (v = R_T·y/r), or ±30° on the sphere.
        let k = projection.fill_tan();
        let s = k * distance / (size.y / 2.0 + k * size.z / 2.0);
        let center = (lo + hi) / 2.0;
        self.transform(
            Mat4::from_translation(Vec3::new(0.0, 0.0, -distance))
                * Mat4::from_scale(Vec3::splat(s))
                * Mat4::from_translation(-center),
        );
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_move_and_turn_the_cameras_with_the_geometry() {
        let mut scene = Scene::new("t");
        let v = |p: [f32; 3]| SceneVertex { position: p, ..Default::default() };
        scene.add_mesh("tri", &[v([0.0, 0.0, -2.0]), v([1.0, 0.0, -2.0]), v([0.0, 1.0, -2.0])], &[0, 1, 2]);
        scene.cameras.push(Camera { name: "c".into(), position: [0.0, 0.5, 0.0], yaw_deg: 30.0 });
        let m = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0))
            * Mat4::from_rotation_y(0.5)
            * Mat4::from_scale(Vec3::splat(2.0));
        scene.transform(m);
        let c = &scene.cameras[0];
        let expected = m.transform_point3(Vec3::new(0.0, 0.5, 0.0));
        assert!((Vec3::from(c.position) - expected).length() < 1e-5, "{:?}", c.position);
        assert!((c.yaw_deg - (30.0 + 0.5f32.to_degrees())).abs() < 1e-3, "{}", c.yaw_deg);
        // The camera keeps its place relative to the first vertex.
        let offset = Vec3::from(scene.vertices[0].position) - Vec3::from(c.position);
        assert!((offset - m.transform_vector3(Vec3::new(0.0, -0.5, -2.0))).length() < 1e-5);
    }
}

/// Per-vertex tangents where a file gives none: MikkTSpace itself (the `bevy_mikktspace` crate),
/// the frame every baker uses and glTF asks for, over the triangles whose vertices all lack one
/// and whose material `wants` one (it has a normal map). Texture coordinates are given v up, as
/// MikkTSpace expects (glTF's v runs down the image): on Khronos NormalTangentMirrorTest this
/// reproduces the file's own tangents, sign included. A vertex the algorithm leaves without a
/// frame (a degenerate triangle without neighbours) keeps none, and the fragment stage falls back
/// to the derivatives' frame. A vertex shared by triangles that MikkTSpace gives different frames
/// (a seam it would split) keeps the last.
pub fn generate_tangents(vertices: &mut [SceneVertex], indices: &[u32], wants: impl Fn(u32) -> bool) {
    let n = vertices.len();
    let needs = |i: u32| (i as usize) < n && vertices[i as usize].tangent == 0 && wants(vertices[i as usize].material);
    let faces: Vec<[u32; 3]> =
        indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).filter(|t| t.iter().all(|&i| needs(i))).collect();
    if faces.is_empty() {
        return;
    }
    let mut mikk = MikkTSpace { vertices, faces: &faces, tangents: vec![None; n] };
    if bevy_mikktspace::generate_tangents(&mut mikk).is_err() {
        return;
    }
    let tangents = mikk.tangents;
    for (v, t) in vertices.iter_mut().zip(tangents) {
        if let Some(t) = t.map(Vec4::from).filter(|t| t.truncate().length() > 0.5) {
            v.tangent = pack_tangent(t);
        }
    }
}

/// A mesh's triangles as MikkTSpace reads them, and the tangents it writes back per vertex.
struct MikkTSpace<'m> {
    vertices: &'m [SceneVertex],
    faces: &'m [[u32; 3]],
    tangents: Vec<Option<[f32; 4]>>,
}

impl MikkTSpace<'_> {
    fn vertex(&self, face: usize, vert: usize) -> &SceneVertex {
        &self.vertices[self.faces[face][vert] as usize]
    }
}

impl bevy_mikktspace::Geometry for MikkTSpace<'_> {
    fn num_faces(&self) -> usize {
        self.faces.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.vertex(face, vert).position
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.vertex(face, vert).normal
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let [u, v] = self.vertex(face, vert).uv;
        [u, 1.0 - v]
    }

    fn set_tangent(&mut self, tangent: Option<bevy_mikktspace::TangentSpace>, face: usize, vert: usize) {
        if let Some(t) = tangent {
            self.tangents[self.faces[face][vert] as usize] = Some(t.tangent_encoded());
        }
    }
}

impl Scene {
    /// Poses the scene's rig (`core::scenes::animation`) at time t of clip `clip` (None: the rest pose):
    /// each mesh instance's vertices (morphed, skinned, moved by its node and the placement),
    /// the nodes' lights and cameras. Nothing happens without a rig.
    pub fn pose(&mut self, clip: Option<usize>, t: f32) {
        self.pose_with(clip, t, true);
    }

    /// The same, the vertices left as they are unless `vertices` (the GPU's skin stage poses
    /// them: `Renderer::pose`).
    pub fn pose_with(&mut self, clip: Option<usize>, t: f32, vertices: bool) {
        use crate::core::scenes::animation::{pose_nodes, pose_vertex, world_matrices};
        let Some(rig) = self.rig.take() else { return };
        let poses = pose_nodes(&rig.nodes, clip.and_then(|c| rig.clips.get(c)), t);
        let world = world_matrices(&rig.nodes, &poses, &rig.order);
        let joint_matrices: Vec<Vec<Mat4>> = rig
            .skins
            .iter()
            .filter(|_| vertices)
            .map(|s| s.joints.iter().zip(&s.inverse_bind).map(|(&j, ib)| world[j] * *ib).collect())
            .collect();
        for inst in rig.instances.iter().filter(|_| vertices) {
            // A skinned mesh is placed by its joints alone (glTF ignores its node's transform).
            let skin = inst.skin.and_then(|s| joint_matrices.get(s)).map(|m| &m[..]);
            let m = rig.placement * if skin.is_some() { Mat4::IDENTITY } else { world[inst.node] };
            let normal_m = m.inverse().transpose();
            let mirror = if glam::Mat3::from_mat4(m).determinant() < 0.0 { -1.0 } else { 1.0 };
            let weights = &poses[inst.node].weights;
            for (i, v) in inst.local.iter().enumerate() {
                let (p, n, tangent) = pose_vertex(v, i, inst, weights, skin);
                let out = &mut self.vertices[inst.first_vertex + i];
                out.position = m.transform_point3(p).into();
                out.normal = normal_m.transform_vector3(n).normalize_or_zero().into();
                if tangent.w != 0.0 {
                    let t = m.transform_vector3(tangent.truncate()).normalize_or_zero();
                    out.tangent = pack_tangent(t.extend(tangent.w * mirror));
                }
            }
        }
        // A point or spot light scaled by s keeps lighting its scaled surroundings as before
        // with s² its intensity (as `Scene::transform` does).
        let scale2 = rig.placement.transform_vector3(Vec3::X).length_squared();
        for &(k, node, light) in &rig.lights {
            if let Some(l) = self.lights.get_mut(k) {
                *l = light.transformed(rig.placement * world[node]);
                if l.kind != crate::core::shading::light::LightKind::Directional {
                    l.color *= scale2;
                }
            }
        }
        for &(k, node) in &rig.cameras {
            if let Some(c) = self.cameras.get_mut(k) {
                let m = rig.placement * world[node];
                let forward = m.transform_vector3(-Vec3::Z);
                c.position = m.transform_point3(Vec3::ZERO).into();
                c.yaw_deg = (-forward.x).atan2(-forward.z).to_degrees();
            }
        }
        self.rig = Some(rig);
    }
}

#[cfg(test)]
mod tangent_tests {
    use glam::{Vec3, Vec4};

    use super::{pack_tangent, unpack_tangent};

    #[test]
    fn tangents_pack_within_two_ten_thousandths_of_a_radian_with_their_sign() {
        let mut worst = 0.0f32;
        for i in 0..2000 {
            // Directions all over the sphere (a spiral), both signs, a few lengths.
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / 2000.0;
            let a = i as f32 * 2.399_963;
            let d = Vec3::new((1.0 - z * z).sqrt() * a.cos(), z, (1.0 - z * z).sqrt() * a.sin());
            let w = if i % 2 == 0 { 1.0 } else { -1.0 };
            let t = unpack_tangent(pack_tangent((d * (0.5 + (i % 3) as f32)).extend(w)));
            assert_eq!(t.w, w);
            // sin of the angle (acos of a dot product near 1 is too coarse in f32).
            worst = worst.max(t.truncate().cross(d).length());
        }
        assert!(worst < 2e-4, "worst {worst} rad");
        for axis in [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z] {
            assert!(unpack_tangent(pack_tangent(axis.extend(1.0))).truncate().cross(axis).length() < 1e-4, "{axis}");
        }
        for none in [Vec4::ZERO, Vec4::new(f32::NAN, 0.0, 1.0, 1.0), Vec4::new(f32::INFINITY, 0.0, 0.0, 1.0)] {
            assert_eq!(pack_tangent(none), 0);
        }
        assert_eq!(unpack_tangent(0), Vec4::ZERO);
    }
}
