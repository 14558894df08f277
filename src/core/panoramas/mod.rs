//! The panoramas and their projection (seed 002 eq. 1–4): the cylinder, the sphere and VR180, the fisheye, the cubemap, CAVE walls, a tracked head.

pub mod cave;
pub mod cubemap;
pub mod fisheye;
pub mod head;
pub mod panorama;
pub mod projection;
pub mod sphere;
