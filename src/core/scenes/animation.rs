//! glTF 2.0 animation (issue 18): keyframe samplers and their interpolation, clips of channels
//! that drive node properties, and a scene's rig — its nodes, the mesh instances they move, skins
//! and morph targets — posed at a time into the scene's vertices, lights and cameras.
//!
//! Interpolation follows the glTF 2.0 specification (Appendix C): STEP holds the previous key;
//! LINEAR blends the two keys around t (rotations by spherical linear interpolation, the shorter
//! way); CUBICSPLINE is the cubic Hermite spline through the keys with the file's in- and
//! out-tangents scaled by the keys' interval,
//! p(s) = (2s³ − 3s² + 1)·v_k + (s³ − 2s² + s)·Δt·b_k + (−2s³ + 3s²)·v_k+1 + (s³ − s²)·Δt·a_k+1,
//! rotations normalised afterwards. Before the first key the first value holds, after the last
//! the last.

use glam::{Mat4, Quat, Vec3, Vec4};

/// How a sampler interpolates between its keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    Step,
    Linear,
    CubicSpline,
}

/// What a channel drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Property {
    Translation,
    Rotation,
    Scale,
    /// Morph target weights.
    Weights,
}

/// A keyframe sampler: key times (seconds, increasing) and `width` numbers per key (per key
/// three groups — in-tangent, value, out-tangent — for CUBICSPLINE).
#[derive(Clone, Debug, PartialEq)]
pub struct Sampler {
    pub times: Vec<f32>,
    pub values: Vec<f32>,
    pub width: usize,
    pub interpolation: Interpolation,
}

impl Sampler {
    /// The `width` numbers of key `k`'s value (its in-tangent with `part` 0, value 1,
    /// out-tangent 2 for CUBICSPLINE).
    fn key(&self, k: usize, part: usize) -> &[f32] {
        let start = match self.interpolation {
            Interpolation::CubicSpline => (3 * k + part) * self.width,
            _ => k * self.width,
        };
        &self.values[start..start + self.width]
    }

    /// The value at time t; `rotation`: the numbers are a quaternion (x, y, z, w).
    pub fn sample(&self, t: f32, rotation: bool) -> Vec<f32> {
        let n = self.times.len();
        let last = n - 1;
        if n == 1 || !(t > self.times[0]) {
            return self.key(0, 1).to_vec();
        }
        if t >= self.times[last] {
            return self.key(last, 1).to_vec();
        }
        // The interval [t_k, t_k+1) holding t.
        let k = self.times.partition_point(|&x| x <= t) - 1;
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        let dt = t1 - t0;
        let s = if dt > 0.0 { (t - t0) / dt } else { 0.0 };
        match self.interpolation {
            Interpolation::Step => self.key(k, 1).to_vec(),
            Interpolation::Linear if rotation => {
                let q = |k| Quat::from_slice(self.key(k, 1)).normalize();
                q(k).slerp(q(k + 1), s).to_array().to_vec()
            }
            Interpolation::Linear => {
                self.key(k, 1).iter().zip(self.key(k + 1, 1)).map(|(a, b)| a + (b - a) * s).collect()
            }
            Interpolation::CubicSpline => {
                let (s2, s3) = (s * s, s * s * s);
                let (h00, h10, h01, h11) =
                    (2.0 * s3 - 3.0 * s2 + 1.0, s3 - 2.0 * s2 + s, -2.0 * s3 + 3.0 * s2, s3 - s2);
                let (v0, b0, v1, a1) = (self.key(k, 1), self.key(k, 2), self.key(k + 1, 1), self.key(k + 1, 0));
                let p: Vec<f32> =
                    (0..self.width).map(|i| h00 * v0[i] + h10 * dt * b0[i] + h01 * v1[i] + h11 * dt * a1[i]).collect();
                if rotation {
                    Quat::from_slice(&p).normalize().to_array().to_vec()
                } else {
                    p
                }
            }
        }
    }
}

/// One channel: a sampler driving a node's property.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    pub node: usize,
    pub property: Property,
    pub sampler: Sampler,
}

/// A named animation: channels played together, from time 0 to `duration` seconds.
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    pub name: String,
    pub channels: Vec<Channel>,
    pub duration: f32,
}

/// A node of the rig: its parent and its rest transform (TRS; a node given by a matrix is
/// decomposed) and morph weights.
#[derive(Clone, Debug, PartialEq)]
pub struct RigNode {
    pub parent: Option<usize>,
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
    pub weights: Vec<f32>,
}

/// A node's local pose at a time.
#[derive(Clone, Debug, PartialEq)]
pub struct Pose {
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
    pub weights: Vec<f32>,
}

impl Pose {
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

/// Every node's local pose in `clip` at time t (rest poses where no channel drives them).
pub fn pose_nodes(nodes: &[RigNode], clip: Option<&Clip>, t: f32) -> Vec<Pose> {
    let mut poses: Vec<Pose> = nodes
        .iter()
        .map(|n| Pose { translation: n.translation, rotation: n.rotation, scale: n.scale, weights: n.weights.clone() })
        .collect();
    for channel in clip.map_or(&[][..], |c| &c.channels[..]) {
        let Some(pose) = poses.get_mut(channel.node) else { continue };
        let rotation = channel.property == Property::Rotation;
        let v = channel.sampler.sample(t, rotation);
        match channel.property {
            Property::Translation => pose.translation = Vec3::from_slice(&v),
            Property::Rotation => pose.rotation = Quat::from_slice(&v).normalize(),
            Property::Scale => pose.scale = Vec3::from_slice(&v),
            Property::Weights => pose.weights = v,
        }
    }
    poses
}

/// World matrices of posed nodes (`order`: parents before children).
pub fn world_matrices(nodes: &[RigNode], poses: &[Pose], order: &[usize]) -> Vec<Mat4> {
    let mut world = vec![Mat4::IDENTITY; nodes.len()];
    for &i in order {
        let local = poses[i].matrix();
        world[i] = match nodes[i].parent {
            Some(p) => world[p] * local,
            None => local,
        };
    }
    world
}

/// A vertex of a mesh instance before posing: in the mesh's own frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LocalVertex {
    pub position: Vec3,
    pub normal: Vec3,
    /// xyz and the bitangent sign; zero: none.
    pub tangent: Vec4,
    /// Up to four joints (indices into the skin's joint list) and their weights.
    pub joints: [u16; 4],
    pub weights: [f32; 4],
}

/// A mesh instance the rig moves: its node, where its vertices are in the scene, its vertices
/// in the mesh's frame, its skin, and its morph targets (per target, position and normal
/// offsets per vertex).
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    pub node: usize,
    pub first_vertex: usize,
    pub local: Vec<LocalVertex>,
    pub skin: Option<usize>,
    pub morph_positions: Vec<Vec<Vec3>>,
    pub morph_normals: Vec<Vec<Vec3>>,
}

/// A skin: its joint nodes and their inverse bind matrices.
#[derive(Clone, Debug, PartialEq)]
pub struct Skin {
    pub joints: Vec<usize>,
    pub inverse_bind: Vec<Mat4>,
}

/// Everything that moves in a scene: nodes, mesh instances, skins, the lights and cameras
/// nodes carry (scene index, node, the light in the node's frame), and the clips.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rig {
    pub nodes: Vec<RigNode>,
    /// Node indices, parents before children.
    pub order: Vec<usize>,
    pub instances: Vec<Instance>,
    pub skins: Vec<Skin>,
    pub lights: Vec<(usize, usize, crate::core::shading::light::Light)>,
    pub cameras: Vec<(usize, usize)>,
    pub clips: Vec<Clip>,
    /// Where the scene was moved after loading (`--scale`, `--fit`: `Scene::transform`), applied
    /// after the pose.
    pub placement: Mat4,
}

/// A skinned or morphed vertex in the mesh frame, before the instance's matrix (`pose_vertex`:
/// the CPU twin of the GPU's skinning pass when there is one).
pub fn pose_vertex(
    v: &LocalVertex,
    i: usize,
    instance: &Instance,
    weights: &[f32],
    joint_matrices: Option<&[Mat4]>,
) -> (Vec3, Vec3, Vec4) {
    let (mut p, mut n) = (v.position, v.normal);
    for (k, w) in weights.iter().enumerate() {
        if *w != 0.0 {
            if let Some(d) = instance.morph_positions.get(k).and_then(|t| t.get(i)) {
                p += *w * *d;
            }
            if let Some(d) = instance.morph_normals.get(k).and_then(|t| t.get(i)) {
                n += *w * *d;
            }
        }
    }
    let Some(joints) = joint_matrices else {
        return (p, n, v.tangent);
    };
    let mut m = Mat4::ZERO;
    for (j, w) in v.joints.iter().zip(v.weights) {
        if w != 0.0 {
            m += joints.get(*j as usize).copied().unwrap_or(Mat4::IDENTITY) * w;
        }
    }
    let t = m.transform_vector3(v.tangent.truncate());
    (m.transform_point3(p), m.transform_vector3(n), t.extend(v.tangent.w))
}

impl Rig {
    /// The clip named `name`, or numbered so.
    pub fn clip_index(&self, name: &str) -> Option<usize> {
        self.clips.iter().position(|c| c.name == name).or_else(|| name.parse().ok().filter(|&k| k < self.clips.len()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sampler(times: &[f32], values: &[f32], width: usize, interpolation: Interpolation) -> Sampler {
        Sampler { times: times.to_vec(), values: values.to_vec(), width, interpolation }
    }

    #[test]
    fn step_and_linear_hold_and_blend_the_keys() {
        let s = sampler(&[1.0, 2.0, 4.0], &[0.0, 10.0, 30.0], 1, Interpolation::Linear);
        assert_eq!(s.sample(0.0, false), [0.0]);
        assert_eq!(s.sample(1.5, false), [5.0]);
        assert_eq!(s.sample(3.0, false), [20.0]);
        assert_eq!(s.sample(9.0, false), [30.0]);
        let s = Sampler { interpolation: Interpolation::Step, ..s };
        assert_eq!(s.sample(1.99, false), [0.0]);
        assert_eq!(s.sample(2.0, false), [10.0]);
        assert_eq!(s.sample(3.9, false), [10.0]);
    }

    #[test]
    fn rotations_slerp_the_shorter_way() {
        // 0° to 90° about y: halfway is 45°.
        let q0 = Quat::IDENTITY;
        let q1 = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let values: Vec<f32> = [q0, q1].iter().flat_map(|q| q.to_array()).collect();
        let s = sampler(&[0.0, 1.0], &values, 4, Interpolation::Linear);
        let half = Quat::from_slice(&s.sample(0.5, true));
        assert!(half.angle_between(Quat::from_rotation_y(std::f32::consts::FRAC_PI_4)) < 1e-5);
        // −q1 is the same rotation: still 45°, not the long way round.
        let values: Vec<f32> = [q0, -q1].iter().flat_map(|q| q.to_array()).collect();
        let s = sampler(&[0.0, 1.0], &values, 4, Interpolation::Linear);
        assert!(
            Quat::from_slice(&s.sample(0.5, true)).angle_between(Quat::from_rotation_y(std::f32::consts::FRAC_PI_4))
                < 1e-5
        );
    }

    #[test]
    fn the_cubic_spline_is_the_hermite_curve_with_tangents_scaled_by_the_interval() {
        // Keys at 0 and 2 s with values 0 and 1; out-tangent of key 0: 1 per s, in-tangent of
        // key 1: 0. Hand-computed at s = 0.5 (t = 1): h00·0 + h10·Δt·1 + h01·1 + h11·Δt·0 with
        // h10 = 0.125, h01 = 0.5, Δt = 2: 0.25 + 0.5 = 0.75.
        let s = sampler(&[0.0, 2.0], &[9.0, 0.0, 1.0, 0.0, 1.0, 9.0], 1, Interpolation::CubicSpline);
        assert!((s.sample(1.0, false)[0] - 0.75).abs() < 1e-6);
        assert_eq!(s.sample(0.0, false), [0.0]);
        assert_eq!(s.sample(2.0, false), [1.0]);
        assert_eq!(s.sample(5.0, false), [1.0], "after the last key, the last value");
    }

    #[test]
    fn children_follow_their_parents() {
        let node = |parent, t: Vec3| RigNode {
            parent,
            translation: t,
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
            weights: Vec::new(),
        };
        let nodes = vec![node(None, Vec3::X), node(Some(0), Vec3::Y)];
        let clip = Clip {
            name: "turn".into(),
            duration: 1.0,
            channels: vec![Channel {
                node: 0,
                property: Property::Rotation,
                sampler: sampler(
                    &[0.0, 1.0],
                    &[Quat::IDENTITY, Quat::from_rotation_z(std::f32::consts::PI)]
                        .iter()
                        .flat_map(|q| q.to_array())
                        .collect::<Vec<_>>(),
                    4,
                    Interpolation::Linear,
                ),
            }],
        };
        let poses = pose_nodes(&nodes, Some(&clip), 1.0);
        let world = world_matrices(&nodes, &poses, &[0, 1]);
        // The parent turned half round z: the child's +y offset points down.
        assert!((world[1].transform_point3(Vec3::ZERO) - Vec3::new(1.0, -1.0, 0.0)).length() < 1e-5);
    }
}
