//! [`Visibility`] through the entity hierarchy: each entity's [`InheritedVisibility`] from its
//! own `Visibility` and its ancestors' (`ChildOf`), computed once per frame in `PostUpdate`.

use crate::components::{InheritedVisibility, Visibility};
use bevy_ecs::prelude::*;

/// Deepest chain of parents followed; Bevy's hierarchy has no cycles, this bounds the walk
/// anyway.
const MAX_DEPTH: usize = 4096;

/// Writes every entity's [`InheritedVisibility`]: `Hidden` hides, `Visible` shows, `Inherited`
/// asks the parent (an ancestor without a `Visibility` counts as `Inherited`; the root as
/// visible). Written only where it changes, so change detection stays quiet.
pub fn propagate_visibility(
    mut nodes: Query<(Entity, &Visibility, &mut InheritedVisibility)>,
    visibility: Query<&Visibility>,
    parents: Query<&ChildOf>,
) {
    for (entity, own, mut inherited) in &mut nodes {
        let mut visible = true;
        let (mut current, mut v) = (entity, *own);
        for _ in 0..MAX_DEPTH {
            match v {
                Visibility::Hidden => {
                    visible = false;
                    break;
                }
                Visibility::Visible => break,
                Visibility::Inherited => {}
            }
            let Ok(child_of) = parents.get(current) else { break };
            current = child_of.parent();
            v = visibility.get(current).copied().unwrap_or(Visibility::Inherited);
        }
        if inherited.0 != visible {
            inherited.0 = visible;
        }
    }
}
