//! [`Visibility`] through the entity hierarchy: each entity's [`InheritedVisibility`] from its
//! own `Visibility` and its ancestors' (`ChildOf`), updated in `PostUpdate` where something
//! changed.
//!
//! The update is change-driven. An entity is *dirty* when its `Visibility`, its `ChildOf` or its
//! `InheritedVisibility` changed since the last run (added included), or it lost its `ChildOf`
//! or its `Visibility`. Each dirty entity's value is resolved from its own `Visibility` and its
//! ancestors', walking up until an ancestor whose value is known (already resolved this run, or
//! `Hidden` / `Visible`, which decide by themselves) or the root; every entity on the way is
//! memoised, so an ancestor shared by many dirty entities is resolved once a run. The walk
//! reads `Visibility` and `ChildOf` only, never a stored `InheritedVisibility` (which may be
//! about to change), so each dirty entity gets its exact value whatever the order they come in:
//! a changed child before its changed parent included. Each dirty entity's value is written
//! and, where it changed, passed down `Children` with an explicit stack, which stops at each
//! clean entity whose stored value it does not change and skips dirty entities (they pass their
//! own value down). A frame without changes costs the change-detection scan only.

use crate::components::{InheritedVisibility, Visibility};
use bevy_ecs::entity::{Entities, EntityHashMap};
use bevy_ecs::prelude::*;

/// How much the last [`propagate_visibility`] run did; written only where the resource exists
/// (tests and diagnostics insert it), so the plugin pays nothing for it.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VisibilityUpdateStats {
    /// Dirty entities: `Visibility`, `ChildOf` or `InheritedVisibility` changed or removed.
    pub dirty: usize,
    /// Values resolved: the dirty entities' and the ancestors' walked for them (each once).
    pub resolved: usize,
    /// Entities visited to pass a changed value down (below the dirty ones).
    pub propagated: usize,
    /// `InheritedVisibility` components written.
    pub written: usize,
}

/// What one run knows of an entity it has resolved.
#[derive(Clone, Copy)]
enum Node {
    /// Lost its `ChildOf` or `Visibility` (dirty), value not resolved yet.
    Pending,
    /// Lost its `ChildOf` or `Visibility` (dirty), with its resolved value.
    Removed(bool),
    /// Resolved value.
    Resolved(bool),
}

/// The hierarchy as the update reads it: own `Visibility` (none counts as `Inherited`), parent
/// and children, with their change ticks.
type Tree<'w, 's> = Query<
    'w,
    's,
    (Option<Ref<'static, Visibility>>, Option<Ref<'static, ChildOf>>, Option<&'static Children>),
>;

/// The stored values, written where the entity has a `Visibility` too.
type Stored<'w, 's> = Query<'w, 's, (Option<Ref<'static, Visibility>>, &'static mut InheritedVisibility)>;

/// Entities whose own inputs changed (or were added) since the last run, with what settling
/// them reads and writes.
type ChangedInputs<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        Option<Ref<'static, Visibility>>,
        Option<&'static ChildOf>,
        Option<&'static Children>,
        Option<&'static mut InheritedVisibility>,
    ),
    Or<(Changed<Visibility>, Changed<ChildOf>, Changed<InheritedVisibility>)>,
>;

/// Updates [`InheritedVisibility`] where it may have changed: `Hidden` hides, `Visible` shows,
/// `Inherited` follows the parent (an ancestor without a `Visibility` counts as `Inherited`; a
/// root is visible). Written only where it changes, so change detection stays quiet; an entity
/// without a `Visibility` keeps whatever `InheritedVisibility` it has.
pub fn propagate_visibility(
    mut queries: ParamSet<(ChangedInputs, Stored)>,
    mut orphaned: RemovedComponents<ChildOf>,
    mut unset: RemovedComponents<Visibility>,
    tree: Tree,
    entities: &Entities,
    stats: Option<ResMut<VisibilityUpdateStats>>,
) {
    // Fresh per run: allocation follows this run's changes, not the largest run's.
    let mut run = Run {
        tree: &tree,
        nodes: EntityHashMap::default(),
        path: Vec::new(),
        stack: Vec::new(),
        done: VisibilityUpdateStats::default(),
        // A well-formed hierarchy has no cycles; a walk longer than there are entities is one.
        limit: entities.len() as usize,
    };
    let removed = run.settle_removed(orphaned.read().chain(unset.read()), &mut queries.p1());
    run.settle_changed(&mut queries.p0(), removed);
    run.pass_down(&mut queries.p1(), removed);
    if let Some(mut stats) = stats {
        stats.set_if_neq(run.done);
    }
}

/// One run of [`propagate_visibility`]: what it has resolved, the values it still has to pass
/// down, and what it did.
struct Run<'t, 'w, 's> {
    tree: &'t Tree<'w, 's>,
    nodes: EntityHashMap<Node>,
    /// Scratch space of [`resolve`].
    path: Vec<Entity>,
    /// Children still to look at, with their parent's value.
    stack: Vec<(Entity, bool)>,
    done: VisibilityUpdateStats,
    /// Longest walk up or down before the hierarchy counts as a cycle.
    limit: usize,
}

impl Run<'_, '_, '_> {
    /// Resolves `entity`'s value ([`resolve`]).
    fn resolve(&mut self, entity: Entity) -> bool {
        resolve(entity, self.tree, &mut self.nodes, &mut self.path, self.limit)
    }

    /// Settles the entities that lost their parent or their `Visibility` (`lost`: the
    /// messages, which may repeat an entity and name despawned ones, which have nothing to
    /// update). Returns whether there was one.
    fn settle_removed(&mut self, lost: impl Iterator<Item = Entity>, stored: &mut Stored) -> bool {
        let tree = self.tree;
        let mut removed = Vec::new();
        for entity in lost {
            if tree.contains(entity) && self.nodes.insert(entity, Node::Pending).is_none() {
                removed.push(entity);
            }
        }
        for &entity in &removed {
            let value = self.resolve(entity);
            let (visibility, inherited) = stored.get_mut(entity).ok().unzip();
            if settle_dirty(visibility.flatten(), inherited, value, &mut self.done.written)
                && let Ok((_, _, Some(children))) = tree.get(entity)
            {
                self.stack.extend(children.iter().map(|child| (child, value)));
            }
        }
        self.done.dirty = removed.len();
        !removed.is_empty()
    }

    /// Settles the entities whose own inputs changed, but those [`Run::settle_removed`]
    /// settled (when `removed`: it settled some).
    fn settle_changed(&mut self, changed: &mut ChangedInputs, removed: bool) {
        // The last parent resolved for a leaf: siblings usually come one after another.
        let mut last_parent: Option<(Entity, bool)> = None;
        let mut leaves = 0;
        for (entity, visibility, child_of, children, inherited) in changed.iter_mut() {
            if removed && matches!(self.nodes.get(&entity), Some(Node::Removed(_))) {
                continue; // settled already
            }
            self.done.dirty += 1;
            let children = children.filter(|c| !c.is_empty());
            let value = if children.is_some() {
                // Recorded, as dirty entities below it may walk through it.
                self.resolve(entity)
            } else {
                // A leaf is no one's ancestor: not recorded, so the many leaves of a large change
                // cost no map entries.
                leaves += 1;
                match (own_value(visibility.as_deref().copied()), child_of) {
                    (Some(value), _) => value,
                    (None, None) => true,
                    (None, Some(child_of)) => match last_parent {
                        Some((parent, value)) if parent == child_of.parent() => value,
                        _ => {
                            let value = self.resolve(child_of.parent());
                            last_parent = Some((child_of.parent(), value));
                            value
                        }
                    },
                }
            };
            if settle_dirty(visibility, inherited, value, &mut self.done.written)
                && let Some(children) = children
            {
                self.stack.extend(children.iter().map(|child| (child, value)));
            }
        }
        self.done.resolved = self.nodes.len() + leaves;
    }

    /// Passes the settled values down to the clean entities below them, down to where a
    /// stored value does not change (`removed`: [`Run::settle_removed`] settled some).
    fn pass_down(&mut self, stored: &mut Stored, removed: bool) {
        let tree = self.tree;
        while let Some((entity, parent)) = self.stack.pop() {
            self.done.propagated += 1;
            if self.done.propagated > self.limit {
                tracing::warn!("the ChildOf hierarchy has a cycle; visibility left partly updated");
                break;
            }
            let Ok((own, child_of, children)) = tree.get(entity) else { continue };
            // A dirty entity was settled above from its exact value and passes that down itself.
            let dirty = own.as_ref().is_some_and(|v| v.is_changed())
                || child_of.as_ref().is_some_and(|c| c.is_changed())
                || (removed && matches!(self.nodes.get(&entity), Some(Node::Pending | Node::Removed(_))));
            if dirty {
                continue;
            }
            let value = own_value(own.as_deref().copied()).unwrap_or(parent);
            let descend = match stored.get_mut(entity) {
                // Written by someone else since the last run: dirty, settled above.
                Ok((_, inherited)) if inherited.is_changed() => false,
                Ok((Some(_), mut inherited)) => {
                    // A clean entity's stored value is current unless an ancestor's changed; when
                    // it already is `value`, so is everything below it.
                    let changed = inherited.0 != value;
                    if changed {
                        inherited.0 = value;
                        self.done.written += 1;
                    }
                    changed
                }
                // No `Visibility`: the value passes through to the children.
                Ok((None, _)) | Err(_) => true,
            };
            if descend && let Some(children) = children {
                self.stack.extend(children.iter().map(|child| (child, value)));
            }
        }
    }
}

/// Writes a dirty entity's resolved `value` where it has a `Visibility` and an
/// `InheritedVisibility`; whether its children must be looked at.
fn settle_dirty(
    visibility: Option<Ref<Visibility>>,
    inherited: Option<Mut<InheritedVisibility>>,
    value: bool,
    written: &mut usize,
) -> bool {
    let (Some(visibility), Some(mut inherited)) = (visibility, inherited) else {
        // Nothing stored to compare with (without a `Visibility` the value passes through).
        return true;
    };
    // The stored value is what the children were last computed from unless it was just added
    // or written by someone else, or the entity only now gained its `Visibility` (before, its
    // children looked through it).
    let trusted = !visibility.is_added() && !inherited.is_changed();
    let changed = inherited.0 != value;
    if changed {
        inherited.0 = value;
        *written += 1;
    }
    changed || !trusted
}

/// The value an entity's own `Visibility` decides by itself; `None` for `Inherited` or none.
fn own_value(own: Option<Visibility>) -> Option<bool> {
    match own {
        Some(Visibility::Hidden) => Some(false),
        Some(Visibility::Visible) => Some(true),
        Some(Visibility::Inherited) | None => None,
    }
}

/// Resolves `entity`'s value, walking up `ChildOf` until an ancestor whose value is known, and
/// records it for every entity on the way in `nodes`. `path` is scratch space.
fn resolve(
    entity: Entity,
    tree: &Tree,
    nodes: &mut EntityHashMap<Node>,
    path: &mut Vec<Entity>,
    limit: usize,
) -> bool {
    path.clear();
    let mut current = entity;
    let value = loop {
        if let Some(Node::Removed(value) | Node::Resolved(value)) = nodes.get(&current) {
            break *value;
        }
        // A parent that no longer exists ends the chain like a root.
        let Ok((own, child_of, _)) = tree.get(current) else { break true };
        path.push(current);
        if let Some(value) = own_value(own.as_deref().copied()) {
            break value;
        }
        match child_of {
            Some(child_of) if path.len() <= limit => current = child_of.parent(),
            // A root (or, past `limit`, a cycle): visible.
            _ => break true,
        }
    };
    for &on_path in path.iter() {
        let node = nodes.entry(on_path).or_insert(Node::Resolved(value));
        if let Node::Pending = node {
            *node = Node::Removed(value);
        }
    }
    value
}
