//! What the sources say about wgpu's device and queue, for `direct_calls.rs`: each file's
//! `use` items (names in scope → the paths they stand for), and across all files the names,
//! fields, functions and traits that stand for, hold, return or are implemented for
//! `wgpu::Device` or `wgpu::Queue`.

use std::collections::{HashMap, HashSet};
use syn::punctuated::Punctuated;
use syn::visit::{self, Visit};
use syn::{ImplItem, ReturnType, Type, UseTree};

/// wgpu's functions that return a device and a queue.
const WGPU_DEVICE_FNS: [&str; 1] = ["request_device"];

/// A path as its identifiers.
pub type Segments = Vec<String>;

pub fn segments(path: &syn::Path) -> Segments {
    path.segments.iter().map(|s| s.ident.to_string()).collect()
}

/// A field's name, or its position in a tuple struct.
pub fn member(m: &syn::Member) -> String {
    match m {
        syn::Member::Named(n) => n.to_string(),
        syn::Member::Unnamed(i) => i.index.to_string(),
    }
}

pub fn ends_with(path: &[String], tail: &[&str]) -> bool {
    path.len() >= tail.len() && path[path.len() - tail.len()..].iter().zip(tail).all(|(a, b)| a == b)
}

/// What one file's `use` items bring into scope.
#[derive(Default)]
pub struct Imports {
    /// Name in scope → the path it stands for.
    names: HashMap<String, Segments>,
    /// Prefixes of glob imports (`use wgpu::PollType::*` gives `["wgpu", "PollType"]`).
    globs: Vec<Segments>,
}

impl Imports {
    pub fn of(file: &syn::File) -> Imports {
        struct Uses(Imports);
        impl Visit<'_> for Uses {
            fn visit_item_use(&mut self, u: &syn::ItemUse) {
                add_use(&u.tree, &mut Vec::new(), &mut self.0);
            }
        }
        let mut uses = Uses(Imports::default());
        uses.visit_file(file);
        uses.0
    }

    /// The paths `path` may stand for: its first identifier replaced by what it was imported as
    /// (repeatedly, for imports of imported names), and, when it was not imported, the path
    /// under each glob import.
    pub fn resolve(&self, path: &[String]) -> Vec<Segments> {
        let mut path = path.to_vec();
        for _ in 0..4 {
            let Some(full) = path.first().and_then(|f| self.names.get(f)) else { break };
            if full.len() == 1 && full[0] == path[0] {
                break;
            }
            path = full.iter().chain(&path[1..]).cloned().collect();
        }
        let mut out: Vec<Segments> =
            self.globs.iter().map(|g| g.iter().chain(&path).cloned().collect()).collect();
        out.push(path);
        out
    }
}

fn add_use(tree: &UseTree, prefix: &mut Segments, out: &mut Imports) {
    match tree {
        UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            add_use(&p.tree, prefix, out);
            prefix.pop();
        }
        UseTree::Name(n) if n.ident == "self" => {
            if let Some(last) = prefix.last() {
                out.names.insert(last.clone(), prefix.clone());
            }
        }
        UseTree::Name(n) => {
            let mut full = prefix.clone();
            full.push(n.ident.to_string());
            out.names.insert(n.ident.to_string(), full);
        }
        UseTree::Rename(r) => {
            let mut full = prefix.clone();
            if r.ident != "self" {
                full.push(r.ident.to_string());
            }
            out.names.insert(r.rename.to_string(), full);
        }
        UseTree::Glob(_) => out.globs.push(prefix.clone()),
        UseTree::Group(g) => {
            for t in &g.items {
                add_use(t, prefix, out);
            }
        }
    }
}

/// What all the files together say about the device and the queue.
#[derive(Default)]
pub struct Known {
    /// Names that stand for `wgpu::Device` or `wgpu::Queue` (type aliases, renames).
    pub aliases: HashSet<String>,
    /// Fields whose type holds a device or a queue.
    pub fields: HashSet<String>,
    /// Functions and methods that return one.
    pub fns: HashSet<String>,
    /// Traits implemented for one (`self` is one in their default methods).
    pub traits: HashSet<String>,
}

impl Known {
    /// Whether `path` (a type or trait path, resolved through `imports`) names the device or
    /// the queue, or a generic parameter in `generics` that stands for one.
    pub fn is_device_path(&self, imports: &Imports, path: &[String], generics: &HashSet<String>) -> bool {
        if path.len() == 1 && generics.contains(&path[0]) {
            return true;
        }
        imports.resolve(path).iter().any(|p| {
            ends_with(p, &["wgpu", "Device"])
                || ends_with(p, &["wgpu", "Queue"])
                || p.last().is_some_and(|l| self.aliases.contains(l))
        })
    }

    /// Whether `ty` holds a device or a queue anywhere (`&wgpu::Device`, `Arc<D>`,
    /// `impl Deref<Target = wgpu::Queue>`, `(Device, Queue)`).
    pub fn mentions_device(&self, imports: &Imports, ty: &Type, generics: &HashSet<String>) -> bool {
        let mut m = Mentions { known: self, imports, generics, found: false };
        m.visit_type(ty);
        m.found
    }

    /// The generic parameters of `generics` whose bounds hold a device or a queue
    /// (`D: Deref<Target = wgpu::Device>`), added to `out`.
    pub fn device_generics(&self, imports: &Imports, generics: &syn::Generics, out: &mut HashSet<String>) {
        let bounded = |bounds: &Punctuated<syn::TypeParamBound, syn::Token![+]>, out: &HashSet<String>| {
            let mut m = Mentions { known: self, imports, generics: out, found: false };
            bounds.iter().for_each(|b| m.visit_type_param_bound(b));
            m.found
        };
        for p in generics.type_params() {
            if bounded(&p.bounds, out) {
                out.insert(p.ident.to_string());
            }
        }
        for pred in generics.where_clause.iter().flat_map(|w| &w.predicates) {
            if let syn::WherePredicate::Type(t) = pred
                && let Type::Path(p) = &t.bounded_ty
                && let Some(name) = p.path.get_ident()
                && bounded(&t.bounds, out)
            {
                out.insert(name.to_string());
            }
        }
    }

    /// Reads the aliases, fields, functions and traits from every file.
    pub fn of(files: &[(String, syn::File, Imports)]) -> Known {
        let mut known = Known::default();
        let none = HashSet::new();
        // Aliases of aliases: until nothing is added.
        loop {
            let before = known.aliases.len();
            for (_, file, imports) in files {
                for (name, path) in &imports.names {
                    if known.is_device_path(imports, path, &none) {
                        known.aliases.insert(name.clone());
                    }
                }
                struct Aliases<'a>(&'a Known, &'a Imports, Vec<String>);
                impl Visit<'_> for Aliases<'_> {
                    fn visit_item_type(&mut self, t: &syn::ItemType) {
                        if self.0.mentions_device(self.1, &t.ty, &HashSet::new()) {
                            self.2.push(t.ident.to_string());
                        }
                    }
                }
                let mut found = Aliases(&known, imports, Vec::new());
                found.visit_file(file);
                let found = found.2;
                known.aliases.extend(found);
            }
            if known.aliases.len() == before {
                break;
            }
        }
        for (_, file, imports) in files {
            let mut read =
                Declarations { known: &known, imports, fields: vec![], fns: vec![], traits: vec![] };
            read.visit_file(file);
            let Declarations { fields, fns, traits, .. } = read;
            known.fields.extend(fields);
            known.fns.extend(fns);
            known.traits.extend(traits);
        }
        known.fns.extend(WGPU_DEVICE_FNS.map(String::from));
        known
    }
}

/// Looks for a path that names the device or the queue in a type or a bound.
struct Mentions<'a> {
    known: &'a Known,
    imports: &'a Imports,
    generics: &'a HashSet<String>,
    found: bool,
}

impl Visit<'_> for Mentions<'_> {
    fn visit_path(&mut self, path: &syn::Path) {
        self.found |= self.known.is_device_path(self.imports, &segments(path), self.generics);
        visit::visit_path(self, path);
    }
}

/// Collects the fields, functions and traits of one file that hold or return a device.
struct Declarations<'a> {
    known: &'a Known,
    imports: &'a Imports,
    fields: Vec<String>,
    fns: Vec<String>,
    traits: Vec<String>,
}

impl Declarations<'_> {
    fn signature(&mut self, sig: &syn::Signature, outer: &HashSet<String>) {
        let mut generics = outer.clone();
        self.known.device_generics(self.imports, &sig.generics, &mut generics);
        if let ReturnType::Type(_, ty) = &sig.output
            && self.known.mentions_device(self.imports, ty, &generics)
        {
            self.fns.push(sig.ident.to_string());
        }
    }
}

impl Visit<'_> for Declarations<'_> {
    fn visit_fields_named(&mut self, fields: &syn::FieldsNamed) {
        for f in &fields.named {
            if self.known.mentions_device(self.imports, &f.ty, &HashSet::new()) {
                self.fields.extend(f.ident.as_ref().map(|i| i.to_string()));
            }
        }
        visit::visit_fields_named(self, fields);
    }

    fn visit_fields_unnamed(&mut self, fields: &syn::FieldsUnnamed) {
        // Tuple fields by position (`.0`).
        for (index, f) in fields.unnamed.iter().enumerate() {
            if self.known.mentions_device(self.imports, &f.ty, &HashSet::new()) {
                self.fields.push(index.to_string());
            }
        }
        visit::visit_fields_unnamed(self, fields);
    }

    fn visit_item_fn(&mut self, f: &syn::ItemFn) {
        self.signature(&f.sig, &HashSet::new());
        visit::visit_item_fn(self, f);
    }

    fn visit_item_impl(&mut self, i: &syn::ItemImpl) {
        let mut generics = HashSet::new();
        self.known.device_generics(self.imports, &i.generics, &mut generics);
        let self_device = self.known.mentions_device(self.imports, &i.self_ty, &generics);
        if self_device {
            generics.insert("Self".into());
            if let Some((_, trait_path, _)) = &i.trait_ {
                self.traits.extend(trait_path.segments.last().map(|s| s.ident.to_string()));
            }
        }
        for item in &i.items {
            if let ImplItem::Fn(f) = item {
                self.signature(&f.sig, &generics);
            }
        }
        visit::visit_item_impl(self, i);
    }

    fn visit_trait_item_fn(&mut self, f: &syn::TraitItemFn) {
        self.signature(&f.sig, &HashSet::new());
        visit::visit_trait_item_fn(self, f);
    }
}
