//! The `skin` stage's tables (issue 18): what it reads once of an animated scene
//! ([`SkinData`]: the vertices in their mesh frames, joints, weights, morph offsets) and per
//! frame ([`SkinFrame`]: instance matrices, joint matrices, morph weights), built from the rig.

use glam::{Mat4, Vec3};

use crate::core::scenes::animation::{pose_nodes, world_matrices, Rig};
use crate::encoding::types::{SkinInstance, SkinSource, NO_SKIN};

/// What the skin stage reads once: a source per posed vertex, the morph offsets (per vertex
/// with targets: position then normal offset per target), and per instance its vertices' box in
/// the mesh frame (morph offsets included) and the joints its vertices use, for the posed
/// scene's bounds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SkinData {
    pub sources: Vec<SkinSource>,
    pub deltas: Vec<[f32; 4]>,
    pub boxes: Vec<(Vec3, Vec3)>,
    pub used_joints: Vec<Vec<u32>>,
}

/// What the skin stage reads per frame: per instance its matrices and where its joints and
/// morph weights are; the joint matrices (every skin's, one after the other); the weights.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SkinFrame {
    pub instances: Vec<SkinInstance>,
    pub joints: Vec<[[f32; 4]; 4]>,
    pub weights: Vec<f32>,
}

impl SkinData {
    /// The tables of `rig`'s instances.
    pub fn of(rig: &Rig) -> SkinData {
        let mut data = SkinData::default();
        for (k, inst) in rig.instances.iter().enumerate() {
            let targets = inst.morph_positions.len();
            let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
            let mut used: Vec<u32> = Vec::new();
            for (i, v) in inst.local.iter().enumerate() {
                let first_delta = if targets > 0 { data.deltas.len() as u32 } else { NO_SKIN };
                // The box holds every weighting of the targets (weights within −1..1 per target).
                let mut reach = Vec3::ZERO;
                for t in 0..targets {
                    let (p, n) = (inst.morph_positions[t][i], inst.morph_normals[t][i]);
                    data.deltas.push(p.extend(0.0).to_array());
                    data.deltas.push(n.extend(0.0).to_array());
                    reach += p.abs();
                }
                lo = lo.min(v.position - reach);
                hi = hi.max(v.position + reach);
                for (j, w) in v.joints.iter().zip(v.weights) {
                    if w != 0.0 && !used.contains(&(*j as u32)) {
                        used.push(*j as u32);
                    }
                }
                data.sources.push(SkinSource {
                    position: v.position.to_array(),
                    instance: k as u32,
                    normal: v.normal.to_array(),
                    vertex: (inst.first_vertex + i) as u32,
                    tangent: v.tangent.to_array(),
                    joints: [
                        v.joints[0] as u32 | (v.joints[1] as u32) << 16,
                        v.joints[2] as u32 | (v.joints[3] as u32) << 16,
                    ],
                    first_delta,
                    _pad: 0,
                    weights: v.weights,
                });
            }
            data.boxes.push((lo, hi));
            data.used_joints.push(used);
        }
        data
    }
}

impl SkinFrame {
    /// The frame of `rig` at time t of clip `clip` (None: the rest pose).
    pub fn of(rig: &Rig, clip: Option<usize>, t: f32) -> SkinFrame {
        let poses = pose_nodes(&rig.nodes, clip.and_then(|c| rig.clips.get(c)), t);
        let world = world_matrices(&rig.nodes, &poses, &rig.order);
        let mut frame = SkinFrame::default();
        let mut skin_offsets = Vec::new();
        for skin in &rig.skins {
            skin_offsets.push(frame.joints.len() as u32);
            frame
                .joints
                .extend(skin.joints.iter().zip(&skin.inverse_bind).map(|(&j, ib)| (world[j] * *ib).to_cols_array_2d()));
        }
        for inst in &rig.instances {
            let skin = inst.skin.filter(|&s| s < rig.skins.len());
            let m = rig.placement * if skin.is_some() { Mat4::IDENTITY } else { world[inst.node] };
            let weights = &poses[inst.node].weights;
            let targets = inst.morph_positions.len();
            frame.instances.push(SkinInstance {
                matrix: m.to_cols_array_2d(),
                normal_matrix: m.inverse().transpose().to_cols_array_2d(),
                first_joint: skin.map_or(NO_SKIN, |s| skin_offsets[s]),
                joint_count: skin.map_or(0, |s| rig.skins[s].joints.len() as u32),
                first_weight: frame.weights.len() as u32,
                weight_count: targets as u32,
                mirror: if glam::Mat3::from_mat4(m).determinant() < 0.0 { -1.0 } else { 1.0 },
                ..Default::default()
            });
            frame.weights.extend((0..targets).map(|k| weights.get(k).copied().unwrap_or(0.0)));
        }
        frame
    }

    /// A box holding every posed vertex (the shadow maps are fitted to it): each instance's
    /// mesh-frame box under its matrix, or, skinned, under each joint its vertices use (a
    /// skinned vertex is a weighted mean of its joints' images).
    pub fn bounds(&self, data: &SkinData) -> Option<(Vec3, Vec3)> {
        let mut out: Option<(Vec3, Vec3)> = None;
        for ((inst, &(lo, hi)), used) in self.instances.iter().zip(&data.boxes).zip(&data.used_joints) {
            if lo.x > hi.x {
                continue;
            }
            let m = Mat4::from_cols_array_2d(&inst.matrix);
            let matrices: Vec<Mat4> = if inst.first_joint == NO_SKIN {
                vec![m]
            } else {
                used.iter()
                    .filter(|&&j| j < inst.joint_count)
                    .filter_map(|&j| self.joints.get((inst.first_joint + j) as usize))
                    .map(|j| m * Mat4::from_cols_array_2d(j))
                    .collect()
            };
            for corner in crate::core::shading::shadow::box_corners(lo, hi, Mat4::IDENTITY) {
                for mm in &matrices {
                    let p = mm.transform_point3(corner);
                    out = Some(out.map_or((p, p), |(a, b)| (a.min(p), b.max(p))));
                }
            }
        }
        out
    }
}
