//! CPU reference light assignment, in the same three phases as the GPU compute passes:
//!
//! 1. **Count**: for every light (in order), find the clusters it passes the chosen test for
//!    (only clusters in its conservative candidate range are tested, see `candidates.rs`) and
//!    count them per cluster.
//! 2. **Prefix sum**: each cluster keeps `min(count, cap)` entries; an exclusive prefix sum of
//!    those gives each cluster's `offset`. Entries beyond the cap are counted in
//!    `dropped_pairs`, the clusters that had them in `clusters_overflowed`.
//! 3. **Fill**: walk the lights in ascending order again and append each light to its
//!    clusters' lists while there is room, so every list is ascending and a cap keeps the
//!    lowest light indices.
//!
//! The result equals testing every (light, cluster) pair with [`ClusterGrid::cluster_aabb`] /
//! [`ClusterGrid::cluster_planes`]; tests check that on random scenes.

use super::candidates::ClusterTables;
use super::cull::ViewSphere;
use super::{ClusterGrid, CullTest};

/// Compacted assignment: per cluster `[offset, count]` into `indices`; each cluster's indices
/// ascending (light order). With a cap, the first `cap` lights in ascending order are kept.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ClusterAssignment {
    /// `[offset, count]` per cluster, in cluster index order; offsets are an exclusive prefix
    /// sum of the counts.
    pub ranges: Vec<[u32; 2]>,
    /// All clusters' light indices, back to back.
    pub indices: Vec<u32>,
    /// (light, cluster) pairs that passed the test but were cut by the cap.
    pub dropped_pairs: u64,
    /// Clusters that had more lights than the cap.
    pub clusters_overflowed: u32,
}

/// Summary numbers of an assignment, for overlays and benchmarks.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ClusterStats {
    /// Number of clusters.
    pub clusters: u32,
    /// Clusters with at least one light.
    pub non_empty: u32,
    /// Entries in the light-index list.
    pub total_entries: u64,
    /// Longest list.
    pub max_per_cluster: u32,
    /// `total_entries / clusters`.
    pub mean_per_cluster: f32,
    /// `total_entries / non_empty` (0 when every cluster is empty).
    pub mean_per_non_empty: f32,
}

impl ClusterAssignment {
    /// The lights of `cluster` (empty for an index out of range).
    pub fn lights_of(&self, cluster: u32) -> &[u32] {
        let Some(&[offset, count]) = self.ranges.get(cluster as usize) else { return &[] };
        let start = offset as usize;
        self.indices.get(start..start + count as usize).unwrap_or(&[])
    }

    /// Summary numbers.
    pub fn stats(&self) -> ClusterStats {
        let clusters = self.ranges.len() as u32;
        let non_empty = self.ranges.iter().filter(|r| r[1] > 0).count() as u32;
        let total_entries: u64 = self.ranges.iter().map(|r| u64::from(r[1])).sum();
        let mean = |n: u32| if n == 0 { 0.0 } else { (total_entries as f64 / f64::from(n)) as f32 };
        ClusterStats {
            clusters,
            non_empty,
            total_entries,
            max_per_cluster: self.ranges.iter().map(|r| r[1]).max().unwrap_or(0),
            mean_per_cluster: mean(clusters),
            mean_per_non_empty: mean(non_empty),
        }
    }
}

/// CPU reference assignment of view-space `lights` to the clusters of `grid` (module docs);
/// `cap` limits each cluster's list (`None`: exact, nothing dropped). The kept entries must
/// number fewer than `u32::MAX` (16 GiB of indices); offsets are `u32` as on the GPU.
pub fn assign_lights(
    grid: &ClusterGrid,
    lights: &[ViewSphere],
    test: CullTest,
    cap: Option<u32>,
) -> ClusterAssignment {
    let tables = ClusterTables::new(grid);
    let mut counts = vec![0u32; grid.cluster_count() as usize];
    // Phase 1: count, remembering each light's clusters for phase 3.
    let mut touched: Vec<u32> = Vec::new();
    let mut light_end: Vec<usize> = Vec::with_capacity(lights.len());
    for light in lights {
        tables.for_each_touched(light, test, |cluster| {
            counts[cluster as usize] += 1;
            touched.push(cluster);
        });
        light_end.push(touched.len());
    }
    let mut assignment = compact(&counts, cap);
    // Phase 3: fill in ascending light order.
    let mut written = vec![0u32; counts.len()];
    let mut start = 0;
    for (light, &end) in light_end.iter().enumerate() {
        for &cluster in &touched[start..end] {
            let [offset, count] = assignment.ranges[cluster as usize];
            let slot = &mut written[cluster as usize];
            if *slot < count {
                assignment.indices[(offset + *slot) as usize] = light as u32;
                *slot += 1;
            }
        }
        start = end;
    }
    assignment
}

/// Phase 2: capped counts → ranges by exclusive prefix sum; `indices` sized, not yet filled.
fn compact(counts: &[u32], cap: Option<u32>) -> ClusterAssignment {
    let cap = cap.unwrap_or(u32::MAX);
    let mut out = ClusterAssignment { ranges: Vec::with_capacity(counts.len()), ..Default::default() };
    let mut offset = 0u32;
    for &count in counts {
        let kept = count.min(cap);
        if count > kept {
            out.dropped_pairs += u64::from(count - kept);
            out.clusters_overflowed += 1;
        }
        out.ranges.push([offset, kept]);
        offset += kept;
    }
    out.indices = vec![0; offset as usize];
    out
}

/// All-pairs assignment with the grid's own bounds: the definition `assign_lights` must equal.
#[cfg(test)]
pub(crate) fn assign_lights_brute_force(
    grid: &ClusterGrid,
    lights: &[ViewSphere],
    test: CullTest,
    cap: Option<u32>,
) -> ClusterAssignment {
    let lists: Vec<Vec<u32>> = (0..grid.cluster_count())
        .map(|i| {
            let c = grid.coords(i);
            let aabb = grid.cluster_aabb(c.x, c.y, c.z);
            let planes = grid.cluster_planes(c.x, c.y, c.z);
            (0..lights.len() as u32)
                .filter(|&l| super::cull::sphere_passes(test, &lights[l as usize], aabb, &planes))
                .collect()
        })
        .collect();
    let counts: Vec<u32> = lists.iter().map(|l| l.len() as u32).collect();
    let mut out = compact(&counts, cap);
    for (list, range) in lists.iter().zip(&out.ranges) {
        let (o, n) = (range[0] as usize, range[1] as usize);
        out.indices[o..o + n].copy_from_slice(&list[..n]);
    }
    out
}
