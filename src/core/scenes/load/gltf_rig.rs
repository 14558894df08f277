//! The rig of an animated glTF file (`core::scenes::animation`): its nodes' rest transforms and
//! parents, the mesh instances with their vertices in the mesh frame (joints, weights, morph
//! targets), skins, and the animations' channels. Read only where the file animates, skins or
//! morphs something; a still file loads as before.

use glam::{Mat4, Quat, Vec3, Vec4};
use gltf::animation::util::ReadOutputs;

use crate::core::scenes::animation::{
    Channel, Clip, Instance, Interpolation, LocalVertex, Property, Rig, RigNode, Sampler, Skin,
};

/// Whether the document needs a rig.
pub fn needs_rig(doc: &gltf::Document) -> bool {
    doc.animations().next().is_some()
        || doc.skins().next().is_some()
        || doc.meshes().flat_map(|m| m.primitives()).any(|p| p.morph_targets().next().is_some())
}

/// The rig's nodes (rest transforms, no parents yet: the loader's walk sets them) and skins.
pub fn rig_nodes(doc: &gltf::Document, buffers: &[gltf::buffer::Data]) -> Rig {
    let nodes = doc
        .nodes()
        .map(|n| {
            let (t, r, s) = n.transform().decomposed();
            let weights =
                n.weights().or_else(|| n.mesh().and_then(|m| m.weights())).map_or_else(Vec::new, <[f32]>::to_vec);
            RigNode {
                parent: None,
                translation: Vec3::from(t),
                rotation: Quat::from_array(r).normalize(),
                scale: Vec3::from(s),
                weights,
            }
        })
        .collect();
    let skins = doc
        .skins()
        .map(|skin| {
            let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
            let reader = skin.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let mut inverse_bind: Vec<Mat4> = reader
                .read_inverse_bind_matrices()
                .map_or_else(Vec::new, |r| r.map(|m| Mat4::from_cols_array_2d(&m)).collect());
            inverse_bind.resize(joints.len(), Mat4::IDENTITY);
            Skin { joints, inverse_bind }
        })
        .collect();
    Rig { nodes, skins, ..Default::default() }
}

/// A primitive's instance: its vertices in the mesh frame (positions, normals, tangents as read,
/// before the node's matrix), joints, weights, morph targets.
pub fn instance<'a, 's, F>(
    node: &gltf::Node,
    reader: &gltf::mesh::Reader<'a, 's, F>,
    first_vertex: usize,
    positions: &[[f32; 3]],
    normals: &[Vec3],
    tangents: Option<&[[f32; 4]]>,
) -> Instance
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let n = positions.len();
    let joints: Vec<[u16; 4]> = reader.read_joints(0).map_or_else(Vec::new, |j| j.into_u16().collect());
    let weights: Vec<[f32; 4]> = reader.read_weights(0).map_or_else(Vec::new, |w| w.into_f32().collect());
    let local = (0..n)
        .map(|i| LocalVertex {
            position: Vec3::from(positions[i]),
            normal: normals.get(i).copied().unwrap_or(Vec3::ZERO),
            tangent: tangents.and_then(|t| t.get(i)).map_or(Vec4::ZERO, |t| Vec4::from(*t)),
            joints: joints.get(i).copied().unwrap_or([0; 4]),
            weights: weights.get(i).copied().unwrap_or([0.0; 4]),
        })
        .collect();
    let (mut morph_positions, mut morph_normals) = (Vec::new(), Vec::new());
    for (p, nrm, _) in reader.read_morph_targets() {
        let take = |v: Option<Vec<[f32; 3]>>| {
            let mut v: Vec<Vec3> = v.unwrap_or_default().into_iter().map(Vec3::from).collect();
            v.resize(n, Vec3::ZERO);
            v
        };
        morph_positions.push(take(p.map(|p| p.collect())));
        morph_normals.push(take(nrm.map(|p| p.collect())));
    }
    Instance {
        node: node.index(),
        first_vertex,
        local,
        skin: node.skin().map(|s| s.index()),
        morph_positions,
        morph_normals,
    }
}

/// The document's animations as clips; a channel whose keys are not finite and increasing, or
/// whose values do not match them, is left out with a warning.
pub fn clips(doc: &gltf::Document, buffers: &[gltf::buffer::Data], warnings: &mut Vec<String>) -> Vec<Clip> {
    doc.animations()
        .map(|anim| {
            let name = anim.name().map_or_else(|| format!("animation {}", anim.index()), str::to_string);
            let mut channels = Vec::new();
            for (k, channel) in anim.channels().enumerate() {
                let reader = channel.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
                let times: Vec<f32> = reader.read_inputs().map_or_else(Vec::new, |r| r.collect());
                let (property, values, width): (Property, Vec<f32>, usize) = match reader.read_outputs() {
                    Some(ReadOutputs::Translations(v)) => (Property::Translation, v.flatten().collect(), 3),
                    Some(ReadOutputs::Rotations(v)) => (Property::Rotation, v.into_f32().flatten().collect(), 4),
                    Some(ReadOutputs::Scales(v)) => (Property::Scale, v.flatten().collect(), 3),
                    Some(ReadOutputs::MorphTargetWeights(v)) => {
                        let v: Vec<f32> = v.into_f32().collect();
                        let keys = times.len().max(1);
                        let per_key = match channel.sampler().interpolation() {
                            gltf::animation::Interpolation::CubicSpline => 3 * keys,
                            _ => keys,
                        };
                        let width = v.len() / per_key;
                        (Property::Weights, v, width)
                    }
                    None => {
                        warnings.push(format!("{name}, channel {k}: no output values; left out"));
                        continue;
                    }
                };
                let interpolation = match channel.sampler().interpolation() {
                    gltf::animation::Interpolation::Step => Interpolation::Step,
                    gltf::animation::Interpolation::Linear => Interpolation::Linear,
                    gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
                };
                let per_key = if interpolation == Interpolation::CubicSpline { 3 * width } else { width };
                let increasing = times.windows(2).all(|w| w[0] <= w[1]);
                if times.is_empty()
                    || width == 0
                    || values.len() != times.len() * per_key
                    || !increasing
                    || !times.iter().chain(&values).all(|x| x.is_finite())
                {
                    warnings.push(format!(
                        "{name}, channel {k}: its keys are not finite and increasing, or its values do not match them; left out"
                    ));
                    continue;
                }
                channels.push(Channel {
                    node: channel.target().node().index(),
                    property,
                    sampler: Sampler { times, values, width, interpolation },
                });
            }
            let duration = channels.iter().filter_map(|c| c.sampler.times.last().copied()).fold(0.0f32, f32::max);
            Clip { name, channels, duration }
        })
        .collect()
}
