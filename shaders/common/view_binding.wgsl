// The view uniform at group 0, binding 0, where every pass that shades surfaces has it: the
// mesh passes (Rust: `SceneResources::view_layout`) and the passes that read the G-buffer.
//!include common/view.wgsl

@group(0) @binding(0) var<uniform> view: ViewUniform;
