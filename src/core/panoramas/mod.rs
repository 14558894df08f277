//! The panoramas and their projection (seed 002 eq. 1–4): one type per panorama behind one
//! interface (`panorama`; the registry `registry`, the name a setting chooses `kind`), each in
//! its own file — the cylinder,
//! the full sphere, VR180, the fisheye, the cubemap, CAVE walls — beside what several share:
//! the frame's parameters (`projection`), the sphere's eye model (`sphere`), a tracked head
//! (`head`).

pub mod cave;
pub mod cubemap;
pub mod cylinder;
pub mod equirect;
pub mod fisheye;
pub mod head;
pub mod kind;
pub mod panorama;
pub mod projection;
pub mod registry;
pub mod sphere;
pub mod vr180;
