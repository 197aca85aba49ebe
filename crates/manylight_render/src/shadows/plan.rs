//! Where each light's maps lie in the atlas: how large the atlas grows, which face edge each
//! light gets when the atlas is full (halved, grown back, or dropped, and counted), and which
//! block it gets, kept from frame to frame while its edge holds so its map can be cached.

use super::requests::{ShadowCaster, ShadowRequest};
use crate::atlas::BlockAllocator;
use crate::gpu_types::{SHADOW_FACES, SHADOW_TILE_COLUMNS};
use std::collections::HashMap;

/// Face rows of a light's block of tiles.
pub const SHADOW_TILE_ROWS: u32 = SHADOW_FACES / SHADOW_TILE_COLUMNS;

/// The smallest atlas edge: an atlas grows from it in powers of two as the lights ask.
pub const MIN_ATLAS_SIZE: u32 = 256;

/// The atlas transform of a tile at texel (`x`, `y`) with edge `edge` in an atlas `atlas`
/// texels wide: (sx, ox, sy, oy) of
/// [`GpuShadowFace::atlas`](crate::gpu_types::GpuShadowFace::atlas).
pub fn tile_transform(x: u32, y: u32, edge: u32, atlas: u32) -> [f32; 4] {
    let (a, e) = (atlas as f32, edge as f32);
    [e / a, (2.0 * x as f32 + e) / a - 1.0, e / a, 1.0 - (2.0 * y as f32 + e) / a]
}

/// Where a light's faces lie in the atlas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowPlacement {
    /// The light.
    pub caster: ShadowCaster,
    /// Top-left texel of its block of tiles.
    pub x: u32,
    /// Top-left texel of its block of tiles.
    pub y: u32,
    /// Face edge it got.
    pub edge: u32,
    /// Face edge it asked for.
    pub asked: u32,
}

/// The frame's atlas: every placed light, and what did not fit.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AtlasPlan {
    /// Placed lights, largest faces first (then by light).
    pub placements: Vec<ShadowPlacement>,
    /// Atlas edge in texels.
    pub atlas_size: u32,
    /// Lights placed with a smaller edge than asked.
    pub downgraded: u32,
    /// Lights not placed.
    pub dropped: u32,
}

impl AtlasPlan {
    /// Fraction of the texels of an atlas `atlas` texels wide in a tile (the texture can be
    /// larger than [`AtlasPlan::atlas_size`]: it is never shrunk).
    pub fn occupancy(&self, atlas: u32) -> f32 {
        let used: u64 =
            self.placements.iter().map(|p| u64::from(p.edge).pow(2) * u64::from(SHADOW_FACES)).sum();
        used as f32 / (u64::from(atlas).pow(2)).max(1) as f32
    }
}

/// Packs blocks of `edges` (sorted largest first) in rows of an `atlas` × `atlas` square;
/// `None` when they do not fit. Each row is as tall as its first block.
fn pack_rows(edges: impl Iterator<Item = u32>, atlas: u32) -> Option<Vec<(u32, u32)>> {
    let (mut x, mut y, mut row) = (0u32, 0u32, 0u32);
    let mut out = Vec::new();
    for edge in edges {
        let (w, h) = (SHADOW_TILE_COLUMNS * edge, SHADOW_TILE_ROWS * edge);
        if x + w > atlas {
            (x, y, row) = (0, y + row, 0);
        }
        if w > atlas || y + h > atlas {
            return None;
        }
        out.push((x, y));
        x += w;
        row = row.max(h);
    }
    Some(out)
}

/// Plans the atlas for `requests` (edges are powers of two of at least `min_edge`): the
/// smallest power-of-two atlas from [`MIN_ATLAS_SIZE`] to `max_atlas` that holds every request
/// as asked, or `max_atlas` with every edge halved until they fit (then the room left given
/// back to the most important) and, at `min_edge`,
/// the least important lights left out. Cost: O(n log n) to sort, then O(n) per halving
/// (at most log2 of the largest edge).
pub fn plan_atlas(requests: &[ShadowRequest], max_atlas: u32, min_edge: u32) -> AtlasPlan {
    // Largest first, then by light: a light keeps its block from frame to frame while the
    // lights before it keep their edges, so its map can be cached.
    let mut order: Vec<ShadowRequest> = requests.to_vec();
    order.sort_by(|a, b| b.edge.cmp(&a.edge).then(a.caster.cmp(&b.caster)));
    let placed = |granted: &[u32], order: &[ShadowRequest], atlas: u32, spots: Vec<(u32, u32)>| AtlasPlan {
        placements: order
            .iter()
            .zip(granted)
            .zip(spots)
            .map(|((r, &edge), (x, y))| ShadowPlacement { caster: r.caster, x, y, edge, asked: r.edge })
            .collect(),
        atlas_size: atlas,
        downgraded: order.iter().zip(granted).filter(|(r, g)| **g < r.edge).count() as u32,
        dropped: 0,
    };
    let mut atlas = MIN_ATLAS_SIZE.min(max_atlas);
    loop {
        if let Some(spots) = pack_rows(order.iter().map(|r| r.edge), atlas) {
            let granted: Vec<u32> = order.iter().map(|r| r.edge).collect();
            return placed(&granted, &order, atlas, spots);
        }
        if atlas >= max_atlas {
            break;
        }
        atlas *= 2;
    }
    // Halve every edge (down to the smallest) until the blocks fit: each light keeps its share
    // of the room, where halving only the largest first would take the lights that asked less
    // down with them (docs/benchmarks.md, "Shadows").
    let mut granted: Vec<u32> = order.iter().map(|r| r.edge).collect();
    loop {
        let largest = granted.iter().copied().max().unwrap_or(min_edge);
        if largest <= min_edge {
            break;
        }
        for g in granted.iter_mut().filter(|g| **g > min_edge) {
            *g /= 2;
        }
        // Halving at the smallest edge brings lights of different asks together; re-sort to
        // keep rows largest first.
        let mut paired: Vec<(ShadowRequest, u32)> =
            order.iter().copied().zip(granted.iter().copied()).collect();
        paired.sort_by(|(a, ga), (b, gb)| gb.cmp(ga).then(a.caster.cmp(&b.caster)));
        order = paired.iter().map(|(r, _)| *r).collect();
        granted = paired.iter().map(|(_, g)| *g).collect();
        if pack_rows(granted.iter().copied(), atlas).is_some() {
            let spots = grow_most_important(&mut order, &mut granted, atlas);
            return placed(&granted, &order, atlas, spots);
        }
    }
    // Every light at the smallest edge and still too many: keep the most important ones.
    let per_row = atlas / (SHADOW_TILE_COLUMNS * min_edge);
    let rows = atlas / (SHADOW_TILE_ROWS * min_edge);
    let capacity = (per_row as usize) * (rows as usize);
    order.sort_by(|a, b| b.importance.total_cmp(&a.importance).then(a.caster.cmp(&b.caster)));
    let kept = order.len().min(capacity);
    let dropped = (order.len() - kept) as u32;
    order.truncate(kept);
    order.sort_by_key(|r| r.caster);
    let granted = vec![min_edge; kept];
    let spots = pack_rows(granted.iter().copied(), atlas).unwrap_or_default();
    AtlasPlan { dropped, ..placed(&granted, &order, atlas, spots) }
}

/// Most rounds of [`grow_most_important`]: each can double a light's edge once, so this many
/// rounds can take a light from a sixteenth of its ask back to all of it.
const GROW_ROUNDS: usize = 4;

/// After halving made every block fit (`granted`, in `order`, fits `atlas`): doubles the edges
/// of the most important lights still below their ask, as many as fit (found by bisection on
/// how many), for up to [`GROW_ROUNDS`] rounds, so the room the last halving freed goes to the
/// lights largest on screen. Leaves `order` and `granted` sorted for packing and returns the
/// blocks' places. Cost: O(n log² n) a round.
fn grow_most_important(
    order: &mut Vec<ShadowRequest>,
    granted: &mut Vec<u32>,
    atlas: u32,
) -> Vec<(u32, u32)> {
    let by_size = |g: &[u32], order: &[ShadowRequest]| {
        let mut idx: Vec<usize> = (0..order.len()).collect();
        idx.sort_by(|&a, &b| g[b].cmp(&g[a]).then(order[a].caster.cmp(&order[b].caster)));
        idx
    };
    for _ in 0..GROW_ROUNDS {
        let mut candidates: Vec<usize> = (0..order.len()).filter(|&i| granted[i] < order[i].edge).collect();
        candidates.sort_by(|&a, &b| {
            order[b].importance.total_cmp(&order[a].importance).then(order[a].caster.cmp(&order[b].caster))
        });
        // The first `k` candidates doubled, sorted for packing, if they fit.
        let grown = |k: usize| {
            let mut g = granted.clone();
            for &i in &candidates[..k] {
                g[i] *= 2;
            }
            let idx = by_size(&g, order);
            pack_rows(idx.iter().map(|&i| g[i]), atlas).map(|_| (idx, g))
        };
        let (mut lo, mut hi) = (0, candidates.len());
        while lo < hi {
            let mid = (lo + hi).div_ceil(2);
            if grown(mid).is_some() { lo = mid } else { hi = mid - 1 }
        }
        let Some((idx, g)) = grown(lo).filter(|_| lo > 0) else { break };
        *order = idx.iter().map(|&i| order[i]).collect();
        *granted = idx.iter().map(|&i| g[i]).collect();
    }
    pack_rows(granted.iter().copied(), atlas).unwrap_or_default()
}

/// Places `target`'s lights (their edges from [`plan_atlas`]) in `alloc`'s atlas so that each
/// keeps its block from the frame before while that block's edge is at most its target and at
/// least half of it; the others (new lights, lights whose edge moved further) get blocks, most
/// important first, at their target edge or, where the atlas has no such block free, the
/// largest free below it (counted as smaller than asked). When a light placed by `target`
/// finds no block at all, every block is given back and all are placed anew, largest first.
/// Lights `target` left out are released. Cost: O(n log n).
pub fn place_stably(
    alloc: &mut BlockAllocator<ShadowCaster>,
    target: &AtlasPlan,
    requests: &[ShadowRequest],
) -> AtlasPlan {
    let importance: HashMap<ShadowCaster, f32> = requests.iter().map(|r| (r.caster, r.importance)).collect();
    let wanted: HashMap<ShadowCaster, u32> = target.placements.iter().map(|p| (p.caster, p.edge)).collect();
    let held: Vec<ShadowCaster> = alloc.keys().collect();
    for caster in held {
        let keep = match (wanted.get(&caster), alloc.block_of(caster)) {
            (Some(&edge), Some(block)) => block.edge <= edge && block.edge * 2 >= edge,
            _ => false,
        };
        if !keep {
            alloc.release(caster);
        }
    }
    let mut order: Vec<&ShadowPlacement> = target.placements.iter().collect();
    order.sort_by(|a, b| {
        let (ia, ib) = (importance.get(&a.caster).unwrap_or(&0.0), importance.get(&b.caster).unwrap_or(&0.0));
        ib.total_cmp(ia).then(a.caster.cmp(&b.caster))
    });
    let place = |alloc: &mut BlockAllocator<ShadowCaster>, p: &ShadowPlacement| {
        let mut edge = p.edge.min(alloc.largest_edge());
        while edge > 0 {
            if alloc.allocate(p.caster, edge).is_some() {
                return true;
            }
            edge /= 2;
        }
        false
    };
    let mut homeless = 0;
    for p in &order {
        if alloc.block_of(p.caster).is_none() && !place(alloc, p) {
            homeless += 1;
        }
    }
    if homeless > 0 {
        // Fragmented: everything anew, largest first (blocks nest, so this packs as tightly as
        // the root blocks allow).
        let held: Vec<ShadowCaster> = alloc.keys().collect();
        for caster in held {
            alloc.release(caster);
        }
        order.sort_by(|a, b| b.edge.cmp(&a.edge).then(a.caster.cmp(&b.caster)));
        homeless = order.iter().filter(|p| !place(alloc, p)).count();
    }
    let placements: Vec<ShadowPlacement> = target
        .placements
        .iter()
        .filter_map(|p| {
            alloc.block_of(p.caster).map(|b| ShadowPlacement { x: b.x, y: b.y, edge: b.edge, ..*p })
        })
        .collect();
    AtlasPlan {
        downgraded: placements.iter().filter(|p| p.edge < p.asked).count() as u32,
        dropped: target.dropped + homeless as u32,
        atlas_size: target.atlas_size.max(alloc.atlas()),
        placements,
    }
}

/// The largest atlas a frame may use: `requested`, or the largest power of two the device's
/// textures (`max_texture` texels) allow when that is smaller, and whether the device limited it.
pub fn atlas_limit(requested: u32, max_texture: u32) -> (u32, bool) {
    let device = 1u32 << (31 - max_texture.max(1).leading_zeros());
    (requested.min(device), device < requested)
}

/// The atlas texel at the top left of tile `tile` of a placement's block.
pub(super) fn tile_of(p: &ShadowPlacement, tile: u32) -> (u32, u32) {
    (p.x + (tile % SHADOW_TILE_COLUMNS) * p.edge, p.y + (tile / SHADOW_TILE_COLUMNS) * p.edge)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_map_the_face_square_onto_their_texels() {
        let [sx, ox, sy, oy] = tile_transform(64, 32, 16, 256);
        // Face corner (-1, 1) (u = 0, top row) lands on texel (64, 32).
        let to_texel = |x: f32| ((x * sx + ox) * 0.5 + 0.5) * 256.0;
        assert!((to_texel(-1.0) - 64.0).abs() < 1e-4);
        assert!((to_texel(1.0) - 80.0).abs() < 1e-4);
        let row = |y: f32| (0.5 - 0.5 * (y * sy + oy)) * 256.0;
        assert!((row(1.0) - 32.0).abs() < 1e-4);
        assert!((row(-1.0) - 48.0).abs() < 1e-4);
    }

    #[test]
    fn a_device_with_small_textures_caps_the_atlas_and_says_so() {
        assert_eq!(atlas_limit(8192, 16384), (8192, false));
        assert_eq!(atlas_limit(8192, 8192), (8192, false));
        assert_eq!(atlas_limit(8192, 4096), (4096, true));
        assert_eq!(atlas_limit(8192, 3000), (2048, true), "a power of two below the limit");
        assert_eq!(atlas_limit(8192, 0), (1, true));
    }

    fn requests(edges: &[u32]) -> Vec<ShadowRequest> {
        edges
            .iter()
            .enumerate()
            .map(|(i, &edge)| ShadowRequest {
                caster: ShadowCaster::Point(i as u32),
                edge,
                importance: edge as f32 + i as f32 * 1e-3,
            })
            .collect()
    }

    fn no_overlap(plan: &AtlasPlan) {
        let rect = |p: &ShadowPlacement| (p.x, p.y, p.x + 3 * p.edge, p.y + 2 * p.edge);
        for (i, a) in plan.placements.iter().enumerate() {
            let ra = rect(a);
            assert!(ra.2 <= plan.atlas_size && ra.3 <= plan.atlas_size, "{a:?} outside {}", plan.atlas_size);
            for b in &plan.placements[i + 1..] {
                let rb = rect(b);
                let apart = ra.2 <= rb.0 || rb.2 <= ra.0 || ra.3 <= rb.1 || rb.3 <= ra.1;
                assert!(apart, "{a:?} overlaps {b:?}");
            }
        }
    }

    /// A full atlas: 300 lights asking 16 to 256.
    fn crowd(shift: u32) -> Vec<ShadowRequest> {
        requests(&(0..300).map(|i| 16 << ((i * 7 + shift) % 5)).collect::<Vec<u32>>())
    }

    #[test]
    fn lights_keep_their_blocks_while_their_edges_hold() {
        let mut alloc = BlockAllocator::new(2048, 16);
        let first = place_stably(&mut alloc, &plan_atlas(&crowd(0), 2048, 16), &crowd(0));
        no_overlap(&first);
        assert_eq!(first.placements.len() + first.dropped as usize, 300);
        // The same frame again: every light where it was.
        let again = place_stably(&mut alloc, &plan_atlas(&crowd(0), 2048, 16), &crowd(0));
        assert_eq!(first.placements, again.placements);
        // Two lights leave, one arrives and the importances change: the rest stay.
        let mut next = crowd(0);
        next.retain(|r| !matches!(r.caster, ShadowCaster::Point(3 | 150)));
        next.push(ShadowRequest { caster: ShadowCaster::Point(999), edge: 64, importance: 1e6 });
        for (i, r) in next.iter_mut().enumerate() {
            r.importance += (i % 3) as f32;
        }
        let moved = place_stably(&mut alloc, &plan_atlas(&next, 2048, 16), &next);
        no_overlap(&moved);
        let before: HashMap<ShadowCaster, ShadowPlacement> =
            first.placements.iter().map(|p| (p.caster, *p)).collect();
        let stayed = moved.placements.iter().filter(|p| before.get(&p.caster) == Some(p)).count();
        assert!(stayed * 10 >= moved.placements.len() * 9, "{stayed} of {} stayed", moved.placements.len());
        assert!(moved.placements.iter().any(|p| p.caster == ShadowCaster::Point(999)));
    }

    #[test]
    fn the_atlas_grows_to_hold_every_request_as_asked() {
        let plan = plan_atlas(&requests(&[64, 32, 32, 16, 16, 16]), 4096, 16);
        assert_eq!(plan.atlas_size, 256);
        assert_eq!((plan.downgraded, plan.dropped), (0, 0));
        assert_eq!(plan.placements.len(), 6);
        no_overlap(&plan);
        // Blocks of 1536 × 1024: one a row at 2048, two at 4096.
        let plan = plan_atlas(&requests(&[512; 4]), 4096, 16);
        assert_eq!(plan.atlas_size, 4096);
        no_overlap(&plan);
    }

    #[test]
    fn a_full_atlas_halves_the_largest_then_drops_the_least_important_and_counts_both() {
        // 10 lights at 512 need 10 blocks of 1536 × 1024: four fit a 4096 atlas.
        let plan = plan_atlas(&requests(&[512; 10]), 4096, 16);
        assert_eq!(plan.placements.len(), 10);
        no_overlap(&plan);
        // Halved to 256 all ten fill 23 % of the atlas; the room left goes back to the most
        // important (the last requests), as much as fits.
        let at = |edge| plan.placements.iter().filter(|p| p.edge == edge).count();
        assert_eq!(at(512) + at(256), 10, "{plan:?}");
        assert!(at(512) >= 2, "{plan:?}");
        assert_eq!(plan.downgraded as usize, at(256));
        let most = plan.placements.iter().filter(|p| p.edge == 512).map(|p| p.caster).min().unwrap();
        assert!(
            plan.placements.iter().filter(|p| p.edge == 256).all(|p| p.caster < most),
            "the larger faces went to the most important: {plan:?}"
        );
        assert!(plan.occupancy(4096) > 0.4, "{}", plan.occupancy(4096));
        // 100 000 lights at the smallest edge cannot all fit: the most important stay.
        let many = requests(&vec![16; 100_000]);
        let plan = plan_atlas(&many, 1024, 16);
        let capacity = (1024 / 48) * (1024 / 32);
        assert_eq!(plan.placements.len(), capacity as usize);
        assert_eq!(plan.dropped, 100_000 - capacity);
        assert!(
            plan.placements.iter().all(|p| p.caster >= ShadowCaster::Point(100_000 - capacity)),
            "the most important are kept"
        );
        no_overlap(&plan);
    }
}
