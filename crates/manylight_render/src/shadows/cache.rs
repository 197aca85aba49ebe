//! Which maps are drawn this frame: a map whose block, light and casters are unchanged keeps
//! its tiles ([`ShadowSettings::cache_maps`]); past [`ShadowSettings::max_redrawn_maps`], the
//! changed point and spot light maps least important keep an earlier frame's map (stale); the
//! rest are drawn. Then the frame's faces, pairs and light tables follow from that choice, and
//! the cache remembers what the atlas holds.

use super::ShadowSettings;
use super::gather::MapWork;
use super::requests::ShadowCaster;
use super::resources::ShadowResources;
use crate::gpu_types::{GpuShadowDraw, GpuShadowLight};

/// What a map in the atlas holds, kept from the frame that drew it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct CachedMap {
    /// Its block's top-left texel: a map is reused only where it lies.
    x: u32,
    y: u32,
    /// Its face edge.
    edge: u32,
    /// Hash of the light and the casters it was drawn from.
    content: u64,
    /// The light table's entry it was drawn with (its origin and depth range).
    light: GpuShadowLight,
}

/// What a placed map gets this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum MapState {
    /// Drawn (its tiles cleared first when other maps are kept).
    Draw,
    /// Unchanged since the frame before: kept.
    Cached,
    /// Changed, but past the redraw budget: the earlier map is kept.
    Stale,
}

impl ShadowResources {
    /// Which maps to draw: a map whose block and content are unchanged is kept; past the
    /// redraw budget, the changed point and spot light maps least important keep theirs.
    pub(super) fn choose_redraws(&self, work: &mut [MapWork], settings: &ShadowSettings) {
        let budget = settings.max_redrawn_maps.map_or(usize::MAX, |n| n as usize);
        let mut changed = Vec::new();
        for (i, w) in work.iter_mut().enumerate() {
            let p = w.placement;
            let kept = self.cache.get(&p.caster).filter(|c| (c.x, c.y, c.edge) == (p.x, p.y, p.edge));
            match kept {
                Some(c) if settings.cache_maps && c.content == w.content => w.state = MapState::Cached,
                Some(_) if matches!(p.caster, ShadowCaster::Point(_)) => changed.push(i),
                _ => {}
            }
        }
        if changed.len() > budget {
            changed.sort_by(|&a, &b| {
                work[b]
                    .importance
                    .total_cmp(&work[a].importance)
                    .then(work[a].placement.caster.cmp(&work[b].placement.caster))
            });
            for &i in &changed[budget..] {
                work[i].state = MapState::Stale;
            }
        }
    }

    /// Applies each map's state: a drawn map's faces and pairs join the frame's, a kept or
    /// stale one keeps its tiles; the light tables get each map's entry and the cache the maps
    /// the atlas will hold.
    pub(super) fn commit_maps(&mut self, work: &[MapWork]) {
        self.next_cache.clear();
        for w in work {
            let p = w.placement;
            let mut entry = w.light;
            match w.state {
                MapState::Draw => {
                    let first_face = self.scratch.gpu_faces.len() as u32;
                    self.scratch.gpu_faces.extend_from_slice(&self.scratch.work_faces[w.faces.clone()]);
                    for &(slot, d) in &self.scratch.work_draws[w.draws.clone()] {
                        self.scratch.by_mesh[slot]
                            .1
                            .push(GpuShadowDraw { instance: d.instance, face: first_face + d.face });
                    }
                    self.report.maps_rendered += 1;
                    if w.directional.is_some() {
                        self.report.cascades_rendered += w.faces.len() as u32;
                    }
                    let map = CachedMap { x: p.x, y: p.y, edge: p.edge, content: w.content, light: w.light };
                    self.next_cache.insert(p.caster, map);
                }
                MapState::Cached => {
                    self.report.maps_cached += 1;
                    let map = CachedMap { x: p.x, y: p.y, edge: p.edge, content: w.content, light: w.light };
                    self.next_cache.insert(p.caster, map);
                }
                MapState::Stale => {
                    // The map of an earlier frame, tested from where it was drawn with today's
                    // biases.
                    let Some(&map) = self.cache.get(&p.caster) else { continue };
                    self.report.maps_stale += 1;
                    entry = GpuShadowLight {
                        tile: w.light.tile,
                        params: [
                            map.light.params[0],
                            map.light.params[1],
                            w.light.params[2],
                            w.light.params[3],
                        ],
                        origin: map.light.origin,
                    };
                    self.next_cache.insert(p.caster, map);
                }
            }
            if let ShadowCaster::Point(k) = p.caster {
                self.scratch.gpu_lights[k as usize] = entry;
            }
            if let Some((i, gpu)) = w.directional {
                self.scratch.gpu_directional[i as usize] = gpu;
            }
        }
        std::mem::swap(&mut self.cache, &mut self.next_cache);
    }
}
