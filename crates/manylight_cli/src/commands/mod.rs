//! What each subcommand does with its parsed arguments: one module per subcommand (the
//! CPU-only tables share one), with the frame drawing of `render` and `check` and the helpers
//! of the measuring commands in leaf modules of their own. The measurements themselves live in
//! the crate's top-level modules (`bench`, `report`, `post`, `views`, `soak`, …).

pub(crate) mod bench;
pub(crate) mod check;
pub(crate) mod compare;
pub(crate) mod cpu_tables;
pub(crate) mod environment_accuracy;
mod headless;
pub(crate) mod plot;
pub(crate) mod post;
pub(crate) mod render;
pub(crate) mod report;
pub(crate) mod shadow_rays;
mod shared;
pub(crate) mod views;
