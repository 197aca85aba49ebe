//! A buddy allocator of the shadow atlas's blocks, so a light keeps its place from frame to
//! frame (and its map can be kept) while lights around it come, go and change size.
//!
//! A light's block is [`SHADOW_TILE_COLUMNS`] × `SHADOW_TILE_ROWS` square tiles of one edge
//! `e`: 3e × 2e texels. A block of edge 2e is exactly 2 × 2 blocks of edge e, so blocks nest
//! like a quadtree. The atlas is covered by root blocks: a column of the largest edge that fits
//! (at most a third of the atlas), then in the strip left on the right a column of the largest
//! edge that fits there, and so on down to the smallest edge (99.6 % of a 4096² atlas with
//! edges from 1024 to 16). Allocating splits the smallest free block that is large enough;
//! releasing merges four free siblings back into their parent.

use crate::gpu_types::{SHADOW_FACES, SHADOW_TILE_COLUMNS};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::hash::Hash;

/// Rows of tiles in a block (the shadow module's `SHADOW_TILE_ROWS`).
const SHADOW_TILE_ROWS: u32 = SHADOW_FACES / SHADOW_TILE_COLUMNS;

/// A block's place in the atlas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockPlace {
    /// Top-left texel.
    pub x: u32,
    /// Top-left texel.
    pub y: u32,
    /// Tile edge in texels (the block is 3 × 2 tiles).
    pub edge: u32,
}

/// A root block of the atlas (level 0 of its quadtree).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Root {
    x: u32,
    y: u32,
    edge: u32,
}

/// A block: `level` halvings below root `root`, at column `ix` and row `iy` of that level's
/// grid inside the root.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
struct Block {
    root: u32,
    level: u32,
    iy: u32,
    ix: u32,
}

/// Blocks of an `atlas` × `atlas` texture handed to keys of type `K`, with tile edges from
/// `min_edge` up to the largest power of two at most a third of the atlas (both powers of
/// two).
#[derive(Clone, Debug)]
pub struct BlockAllocator<K> {
    atlas: u32,
    min_edge: u32,
    roots: Vec<Root>,
    /// Free blocks by tile edge.
    free: BTreeMap<u32, BTreeSet<Block>>,
    owned: HashMap<K, Block>,
}

impl<K: Copy + Eq + Hash> BlockAllocator<K> {
    /// An allocator with the whole atlas free.
    pub fn new(atlas: u32, min_edge: u32) -> BlockAllocator<K> {
        let min_edge = min_edge.max(1);
        let mut roots = Vec::new();
        let mut left = 0u32;
        // Columns of roots, each of the largest edge that fits the strip left on the right.
        loop {
            let room = atlas - left;
            let widest = room / SHADOW_TILE_COLUMNS;
            if widest < min_edge {
                break;
            }
            let edge = 1u32 << (31 - widest.leading_zeros());
            let (w, h) = (SHADOW_TILE_COLUMNS * edge, SHADOW_TILE_ROWS * edge);
            let columns = room / w;
            for c in 0..columns {
                for r in 0..atlas / h {
                    roots.push(Root { x: left + c * w, y: r * h, edge });
                }
            }
            left += columns * w;
        }
        let mut free: BTreeMap<u32, BTreeSet<Block>> = BTreeMap::new();
        for (i, root) in roots.iter().enumerate() {
            free.entry(root.edge).or_default().insert(Block { root: i as u32, level: 0, iy: 0, ix: 0 });
        }
        BlockAllocator { atlas, min_edge, roots, free, owned: HashMap::new() }
    }

    /// True when this allocator serves an `atlas`-texel texture with tiles down to `min_edge`.
    pub fn serves(&self, atlas: u32, min_edge: u32) -> bool {
        self.atlas == atlas && self.min_edge == min_edge.max(1)
    }

    /// Edge of the atlas it serves, in texels.
    pub fn atlas(&self) -> u32 {
        self.atlas
    }

    /// The largest tile edge a block can have.
    pub fn largest_edge(&self) -> u32 {
        self.roots.iter().map(|r| r.edge).max().unwrap_or(0)
    }

    fn edge(&self, b: Block) -> u32 {
        self.roots[b.root as usize].edge >> b.level
    }

    fn place(&self, b: Block) -> BlockPlace {
        let root = self.roots[b.root as usize];
        let edge = self.edge(b);
        BlockPlace {
            x: root.x + b.ix * SHADOW_TILE_COLUMNS * edge,
            y: root.y + b.iy * SHADOW_TILE_ROWS * edge,
            edge,
        }
    }

    /// Where `key`'s block lies, if it has one.
    pub fn block_of(&self, key: K) -> Option<BlockPlace> {
        self.owned.get(&key).map(|&b| self.place(b))
    }

    /// Every key holding a block.
    pub fn keys(&self) -> impl Iterator<Item = K> + '_ {
        self.owned.keys().copied()
    }

    /// Gives `key`'s block back (nothing when it has none); four free siblings merge.
    pub fn release(&mut self, key: K) {
        let Some(mut block) = self.owned.remove(&key) else { return };
        loop {
            let edge = self.edge(block);
            if block.level == 0 {
                self.free.entry(edge).or_default().insert(block);
                return;
            }
            let (px, py) = (block.ix / 2, block.iy / 2);
            let siblings: Vec<Block> = (0..4)
                .map(|i| Block {
                    root: block.root,
                    level: block.level,
                    ix: px * 2 + i % 2,
                    iy: py * 2 + i / 2,
                })
                .filter(|s| *s != block)
                .collect();
            let set = self.free.entry(edge).or_default();
            if !siblings.iter().all(|s| set.contains(s)) {
                set.insert(block);
                return;
            }
            for s in &siblings {
                set.remove(s);
            }
            block = Block { root: block.root, level: block.level - 1, ix: px, iy: py };
        }
    }

    /// A block of tile edge `edge` (a power of two from the smallest to
    /// [`BlockAllocator::largest_edge`]) for `key`, which must hold none; `None` when no free
    /// block is that large. Takes the first free block of that edge, else splits the smallest
    /// larger one.
    pub fn allocate(&mut self, key: K, edge: u32) -> Option<BlockPlace> {
        debug_assert!(!self.owned.contains_key(&key), "the key holds a block");
        if edge < self.min_edge || !edge.is_power_of_two() {
            return None;
        }
        let (&found, _) = self.free.range(edge..).find(|(_, set)| !set.is_empty())?;
        let mut block = self.free.get_mut(&found)?.pop_first()?;
        let mut block_edge = found;
        while block_edge > edge {
            // Split: keep the first child, free the other three.
            block_edge /= 2;
            let (ix, iy, level) = (block.ix * 2, block.iy * 2, block.level + 1);
            let set = self.free.entry(block_edge).or_default();
            for i in 1..4 {
                set.insert(Block { root: block.root, level, ix: ix + i % 2, iy: iy + i / 2 });
            }
            block = Block { root: block.root, level, ix, iy };
        }
        self.owned.insert(key, block);
        Some(self.place(block))
    }

    /// Texels in free blocks.
    pub fn free_texels(&self) -> u64 {
        let block = |edge: u32| u64::from(SHADOW_TILE_COLUMNS * edge) * u64::from(SHADOW_TILE_ROWS * edge);
        self.free.iter().map(|(&edge, set)| block(edge) * set.len() as u64).sum()
    }

    /// Texels the root blocks cover.
    pub fn covered_texels(&self) -> u64 {
        self.roots
            .iter()
            .map(|r| u64::from(SHADOW_TILE_COLUMNS * r.edge) * u64::from(SHADOW_TILE_ROWS * r.edge))
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn overlaps(a: BlockPlace, b: BlockPlace) -> bool {
        let (aw, ah) = (SHADOW_TILE_COLUMNS * a.edge, SHADOW_TILE_ROWS * a.edge);
        let (bw, bh) = (SHADOW_TILE_COLUMNS * b.edge, SHADOW_TILE_ROWS * b.edge);
        a.x < b.x + bw && b.x < a.x + aw && a.y < b.y + bh && b.y < a.y + ah
    }

    fn assert_disjoint_inside(alloc: &BlockAllocator<u32>) {
        let placed: Vec<BlockPlace> = alloc.keys().filter_map(|k| alloc.block_of(k)).collect();
        for (i, a) in placed.iter().enumerate() {
            assert!(
                a.x + SHADOW_TILE_COLUMNS * a.edge <= alloc.atlas
                    && a.y + SHADOW_TILE_ROWS * a.edge <= alloc.atlas
            );
            for b in &placed[i + 1..] {
                assert!(!overlaps(*a, *b), "{a:?} overlaps {b:?}");
            }
        }
    }

    #[test]
    fn roots_cover_nearly_all_of_the_atlas() {
        let alloc = BlockAllocator::<u32>::new(4096, 16);
        assert_eq!(alloc.largest_edge(), 1024);
        let share = alloc.covered_texels() as f64 / 4096f64.powi(2);
        assert!(share > 0.99, "{share}");
        assert_eq!(alloc.free_texels(), alloc.covered_texels());
    }

    #[test]
    fn blocks_never_overlap_and_release_merges_them_back() {
        let mut alloc = BlockAllocator::<u32>::new(2048, 16);
        let total = alloc.free_texels();
        let edges = [512, 16, 64, 256, 16, 32, 128, 16, 64];
        for (k, &e) in edges.iter().cycle().take(120).enumerate() {
            alloc.allocate(k as u32, e);
        }
        assert_disjoint_inside(&alloc);
        for k in (0..120).step_by(2) {
            alloc.release(k);
        }
        assert_disjoint_inside(&alloc);
        for k in (1..120).step_by(2) {
            alloc.release(k);
        }
        assert_eq!(alloc.free_texels(), total);
        // Everything merged back: the largest blocks can be had again.
        let roots = alloc.roots.iter().filter(|r| r.edge == alloc.largest_edge()).count();
        for k in 0..roots as u32 {
            assert!(alloc.allocate(k, alloc.largest_edge()).is_some());
        }
    }

    #[test]
    fn a_block_stays_where_it_is_while_others_come_and_go() {
        let mut alloc = BlockAllocator::<u32>::new(1024, 16);
        let kept = alloc.allocate(0, 64).expect("room");
        for round in 0..10u32 {
            for k in 1..40 {
                alloc.allocate(k, 16 << ((k + round) % 4));
            }
            for k in 1..40 {
                alloc.release(k);
            }
            assert_eq!(alloc.block_of(0), Some(kept));
        }
    }

    #[test]
    fn a_full_atlas_refuses_and_odd_edges_are_refused() {
        let mut alloc = BlockAllocator::<u32>::new(256, 16);
        assert_eq!(alloc.allocate(0, 24), None);
        assert_eq!(alloc.allocate(0, 8), None);
        let mut k = 0;
        while alloc.allocate(k, 16).is_some() {
            k += 1;
        }
        assert_eq!(alloc.free_texels(), 0);
        assert_eq!(k, 40, "two roots of edge 64 (16 blocks each) and eight of edge 16");
    }
}
