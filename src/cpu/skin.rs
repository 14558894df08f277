//! The `skin` stage, CPU twin of `shaders/skin.wgsl` (issue 18): an animated scene's vertices
//! posed from tables — uploaded once, the vertices in their mesh frames with joints, weights and
//! morph offsets ([`SkinData`]); per frame only each instance's matrices and each skin's joint
//! matrices and morph weights ([`SkinFrame`]) — exactly as `Scene::pose` poses them on the CPU
//! (morph offsets × weights, then Σ wⱼ·Jⱼ for a skinned vertex, then the instance's matrix; the
//! normal by the inverse transpose; the tangent by the matrix, its sign flipped by a mirroring
//! one).

use glam::{Mat4, Vec3, Vec4};

use crate::core::scenes::scene::{pack_tangent, SceneVertex};
pub use crate::encoding::skin::{SkinData, SkinFrame};
use crate::encoding::types::NO_SKIN;

/// The `skin` stage on the CPU: every source's posed vertex written into `vertices` (position,
/// normal, and the tangent where the source has one).
pub fn skin(data: &SkinData, frame: &SkinFrame, vertices: &mut [SceneVertex]) {
    for s in &data.sources {
        let inst = &frame.instances[s.instance as usize];
        let (mut p, mut n) = (Vec3::from(s.position), Vec3::from(s.normal));
        if s.first_delta != NO_SKIN {
            for k in 0..inst.weight_count {
                let w = frame.weights[(inst.first_weight + k) as usize];
                if w != 0.0 {
                    p += w * Vec4::from(data.deltas[(s.first_delta + 2 * k) as usize]).truncate();
                    n += w * Vec4::from(data.deltas[(s.first_delta + 2 * k + 1) as usize]).truncate();
                }
            }
        }
        let mut t = Vec4::from(s.tangent).truncate();
        if inst.first_joint != NO_SKIN {
            let joints = [s.joints[0] & 0xffff, s.joints[0] >> 16, s.joints[1] & 0xffff, s.joints[1] >> 16];
            let mut m = Mat4::ZERO;
            for (&j, w) in joints.iter().zip(s.weights) {
                if w != 0.0 {
                    // A joint beyond the skin's list counts as the identity (as `pose_vertex`).
                    let joint = if j < inst.joint_count {
                        Mat4::from_cols_array_2d(&frame.joints[(inst.first_joint + j) as usize])
                    } else {
                        Mat4::IDENTITY
                    };
                    m += joint * w;
                }
            }
            (p, n, t) = (m.transform_point3(p), m.transform_vector3(n), m.transform_vector3(t));
        }
        let m = Mat4::from_cols_array_2d(&inst.matrix);
        let out = &mut vertices[s.vertex as usize];
        out.position = m.transform_point3(p).into();
        out.normal = Mat4::from_cols_array_2d(&inst.normal_matrix).transform_vector3(n).normalize_or_zero().into();
        if s.tangent[3] != 0.0 {
            out.tangent = pack_tangent(m.transform_vector3(t).normalize_or_zero().extend(s.tangent[3] * inst.mirror));
        }
    }
}
