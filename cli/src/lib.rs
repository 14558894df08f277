//! The `twister` command line as a library: its options (clap), the commands that render,
//! measure, view and benchmark, and what they write. The binary (main.rs) parses the command
//! line and calls them; the Python package (python/) takes the same options by name, so a
//! keyword argument means exactly what the option means and draws the same pixels.

// Comparisons written `!(x > y)` are deliberate: they put NaN on the rejecting side.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod args;
pub mod bench;
pub mod cave;
pub mod choice;
pub mod flags;
pub mod heatmap;
pub mod info;
pub mod measure;
pub mod plot;
pub mod render;
pub mod scene;
pub mod sequence;
pub mod tiled;
pub mod view;
pub mod writer;
