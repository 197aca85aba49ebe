// The light lists a shading pass reads (group 2; Rust: `ClusterResources::shading_layout`): the
// cluster ranges and light indices the build writes and, where the view refines its lists
// (light_refine.wgsl), its pixel blocks' ranges after them.
//!include common/clusters.wgsl

@group(2) @binding(0) var<uniform> cluster_params: ClusterParams;
@group(2) @binding(1) var<storage, read> cluster_ranges: array<vec2<u32>>;
@group(2) @binding(2) var<storage, read> cluster_indices: array<u32>;

// The (offset, count) in `cluster_indices` of the list a fragment at framebuffer position
// `frag` (pixels) and view distance `d` shades from: its block's refined list, or, without
// one, its cluster's; a count of LIST_EVERY_LIGHT when it shades from every light (its
// cluster's list did not fit the frame's lists).
fn light_list_range(frag: vec2<f32>, d: f32) -> vec2<u32> {
    let blocks = vec2<u32>(cluster_params.refine_blocks_x, cluster_params.refine_blocks_y);
    if blocks.x != 0u {
        let b = min(vec2<u32>(max(frag, vec2<f32>(0.0))) / REFINE_EDGE, blocks - 1u);
        let r = cluster_ranges[refined_range_index(cluster_params, b)];
        if r.y != REFINED_FALLBACK {
            return r;
        }
    }
    return cluster_ranges[cluster_index(cluster_params, frag, d)];
}
