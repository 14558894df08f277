//! Visual-field level of detail (seeds 000/001): the visual field, the budgets and the simplified levels.

pub mod lod;
pub mod simplify;
pub mod visual_field;
