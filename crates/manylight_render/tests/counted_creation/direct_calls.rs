//! Finds, in parsed Rust sources, every call that reaches wgpu's device or queue to create a
//! buffer or bind group, upload, or poll, outside `impl GpuContext` (which counts them).
//!
//! The receiver's type is what matters, not its name, so the finder follows the code:
//! 1. Each file's `use` items are read into a map from the names in scope to the paths they
//!    stand for (renames, groups, globs), so `use wgpu::Device as D` makes `D` the device
//!    (`known.rs`).
//! 2. Across all files: the names that stand for `wgpu::Device` or `wgpu::Queue` (type aliases,
//!    renamed re-exports), the struct fields of such a type (`GpuContext::device` and any
//!    other), the functions and methods returning one, and the traits implemented for one
//!    (`known.rs`).
//! 3. Each function is walked with its bindings: parameters and `let`s of such a type or taking
//!    such a value (`let d = &gpu.device;`, destructured fields, tuples), `self` in an impl for
//!    one (or in a trait implemented for one), and closure parameters fed one.
//! 4. A method call named as one of [`DIRECT`] on such a receiver is a finding; so is such a
//!    method named by path (`wgpu::Device::create_buffer`, `DeviceExt::create_buffer_init`,
//!    `<D as DeviceExt>::...`), any `PollType` value but `Poll` (a blocking wait), and the
//!    wgpu helpers that create buffers themselves ([`HELPERS`]). Macro arguments are read as
//!    expressions; tokens that do not parse are searched for the method names.

use crate::known::{Imports, Known, Segments, ends_with, member, segments};
use proc_macro2::{TokenStream, TokenTree};
use std::collections::{HashMap, HashSet};
use syn::punctuated::Punctuated;
use syn::spanned::Spanned;
use syn::visit::{self, Visit};
use syn::{Expr, FnArg, Item, Pat, Type};

/// Methods of `wgpu::Device`, `wgpu::Queue` and `wgpu::util::DeviceExt` that create a buffer
/// or bind group, hand bytes to the GPU or poll the device, and what to call instead.
pub const DIRECT: [(&str, &str); 8] = [
    ("create_buffer", "GpuContext::create_buffer"),
    ("create_buffer_init", "GpuContext::create_buffer_init"),
    ("create_bind_group", "GpuContext::create_bind_group"),
    ("create_texture_with_data", "a texture written with GpuContext::write_texture"),
    ("write_buffer", "GpuContext::write_buffer"),
    ("write_buffer_with", "GpuContext::write_buffer"),
    ("write_texture", "GpuContext::write_texture"),
    ("poll", "GpuContext::poll or GpuContext::wait_for (a raw poll may only be `PollType::Poll`)"),
];

/// wgpu helpers that create and fill buffers of their own: naming one is a finding.
pub const HELPERS: [(&str, &str); 2] = [
    ("StagingBelt", "GpuContext::write_buffer"),
    ("DownloadBuffer", "a buffer from GpuContext::create_buffer"),
];

/// Methods that hand back (a reference to) the value they are called on.
const PASS_THROUGH: [&str; 10] =
    ["clone", "as_ref", "borrow", "deref", "to_owned", "unwrap", "expect", "as_deref", "lock", "read"];

/// The file `impl GpuContext` lives in: its methods are the counted calls.
pub const CONTEXT_FILE: &str = "manylight_render/src/context.rs";

/// Walks one file's code with its bindings and records the findings.
struct Finder<'a> {
    file: &'a str,
    known: &'a Known,
    imports: &'a Imports,
    /// Bindings in scope, innermost last: name → holds a device or a queue.
    scopes: Vec<HashMap<String, bool>>,
    /// Generic parameters (and `Self`) standing for a device or a queue, per item.
    generics: Vec<HashSet<String>>,
    /// Whether `self` is a device or a queue, per item.
    self_device: Vec<bool>,
    /// Whether a closure being visited is an argument of a call fed a device or a queue.
    fed_device: bool,
    findings: Vec<String>,
}

impl Finder<'_> {
    fn finding(&mut self, at: proc_macro2::Span, what: String, instead: &str) {
        self.findings.push(format!("{}:{}: {what}, use {instead}", self.file, at.start().line));
    }

    fn generics(&self) -> HashSet<String> {
        self.generics.last().cloned().unwrap_or_default()
    }

    fn type_is_device(&self, ty: &Type) -> bool {
        self.known.mentions_device(self.imports, ty, &self.generics())
    }

    fn lookup(&self, name: &str) -> bool {
        if name == "self" {
            return self.self_device.last().copied().unwrap_or(false);
        }
        self.scopes.iter().rev().find_map(|s| s.get(name).copied()).unwrap_or(false)
    }

    /// Whether `e` is (a reference to) a device or a queue.
    fn is_device(&self, e: &Expr) -> bool {
        match e {
            Expr::Path(p) if p.qself.is_none() => {
                p.path.get_ident().is_some_and(|i| self.lookup(&i.to_string()))
            }
            Expr::Field(f) => self.known.fields.contains(&member(&f.member)),
            Expr::Reference(r) => self.is_device(&r.expr),
            Expr::Paren(p) => self.is_device(&p.expr),
            Expr::Group(g) => self.is_device(&g.expr),
            Expr::Unary(u) => matches!(u.op, syn::UnOp::Deref(_)) && self.is_device(&u.expr),
            Expr::Try(t) => self.is_device(&t.expr),
            Expr::Await(a) => self.is_device(&a.base),
            Expr::Cast(c) => self.is_device(&c.expr),
            Expr::Index(i) => self.is_device(&i.expr),
            Expr::MethodCall(m) => {
                let name = m.method.to_string();
                self.known.fns.contains(&name)
                    || (PASS_THROUGH.contains(&name.as_str()) && self.is_device(&m.receiver))
            }
            Expr::Call(c) => match &*c.func {
                Expr::Path(p) => {
                    let name = p.path.segments.last().map(|s| s.ident.to_string()).unwrap_or_default();
                    self.known.fns.contains(&name)
                        || (name == "clone" && c.args.first().is_some_and(|a| self.is_device(a)))
                }
                _ => false,
            },
            _ => false,
        }
    }

    /// Whether `e` or any expression inside it is a device or a queue.
    fn contains_device(&self, e: &Expr) -> bool {
        struct Contains<'f, 'a>(&'f Finder<'a>, bool);
        impl Visit<'_> for Contains<'_, '_> {
            fn visit_expr(&mut self, e: &Expr) {
                self.1 |= self.0.is_device(e);
                if !self.1 {
                    visit::visit_expr(self, e);
                }
            }
        }
        let mut c = Contains(self, false);
        c.visit_expr(e);
        c.1
    }

    /// Binds the names of `pat`: devices when `device`, or when they take a device field.
    fn bind(&mut self, pat: &Pat, device: bool) {
        match pat {
            Pat::Ident(i) => {
                if let Some(scope) = self.scopes.last_mut() {
                    scope.insert(i.ident.to_string(), device);
                }
                if let Some((_, sub)) = &i.subpat {
                    self.bind(sub, device);
                }
            }
            Pat::Type(t) => {
                let device = device || self.type_is_device(&t.ty);
                self.bind(&t.pat, device);
            }
            Pat::Struct(s) => {
                for f in &s.fields {
                    let field = self.known.fields.contains(&member(&f.member));
                    self.bind(&f.pat, device || field);
                }
            }
            Pat::Reference(r) => self.bind(&r.pat, device),
            Pat::Paren(p) => self.bind(&p.pat, device),
            Pat::Tuple(t) => t.elems.iter().for_each(|p| self.bind(p, device)),
            Pat::TupleStruct(t) => t.elems.iter().for_each(|p| self.bind(p, device)),
            Pat::Slice(s) => s.elems.iter().for_each(|p| self.bind(p, device)),
            Pat::Or(o) => o.cases.iter().for_each(|p| self.bind(p, device)),
            _ => {}
        }
    }

    /// Binds `pat = init`: element by element for a tuple pattern and a tuple expression.
    fn bind_init(&mut self, pat: &Pat, init: Option<&Expr>) {
        match (pat, init) {
            (Pat::Tuple(p), Some(Expr::Tuple(e))) if p.elems.len() == e.elems.len() => {
                for (p, e) in p.elems.iter().zip(&e.elems) {
                    self.bind_init(p, Some(e));
                }
            }
            (pat, init) => {
                let device = init.is_some_and(|e| self.is_device(e));
                self.bind(pat, device);
            }
        }
    }

    /// A function's parameters and body in a scope of their own.
    fn function(&mut self, sig: &syn::Signature, body: Option<&syn::Block>) {
        let mut generics = self.generics();
        self.known.device_generics(self.imports, &sig.generics, &mut generics);
        self.generics.push(generics);
        self.scopes.push(HashMap::new());
        for input in &sig.inputs {
            if let FnArg::Typed(t) = input {
                let device = self.type_is_device(&t.ty);
                self.bind(&t.pat, device);
            }
        }
        if let Some(body) = body {
            self.visit_block(body);
        }
        self.scopes.pop();
        self.generics.pop();
    }

    /// Whether a poll's arguments are `PollType::Poll` (checking for finished work without
    /// waiting, which no counter counts).
    fn polls_without_waiting(&self, args: &Punctuated<Expr, syn::Token![,]>) -> bool {
        match args.first() {
            Some(Expr::Path(p)) if args.len() == 1 => {
                self.imports.resolve(&segments(&p.path)).iter().any(|r| ends_with(r, &["PollType", "Poll"]))
            }
            _ => false,
        }
    }

    /// Visits call arguments, telling closures among them whether the call is fed a device.
    fn arguments<'e>(&mut self, fed: bool, args: impl Iterator<Item = &'e Expr>) {
        let outer = std::mem::replace(&mut self.fed_device, fed);
        for a in args {
            self.visit_expr(a);
        }
        self.fed_device = outer;
    }

    /// Checks a path (in an expression, a type or a pattern): a direct method named through
    /// its type or trait, a `PollType` other than `Poll`, or a helper that creates buffers.
    fn check_path(&mut self, path: &syn::Path) {
        let raw = segments(path);
        for resolved in self.imports.resolve(&raw) {
            if let Some(i) = resolved.iter().position(|s| s == "PollType")
                && let Some(variant) = resolved.get(i + 1)
                && variant != "Poll"
            {
                let what = format!("`{}` (a blocking wait)", resolved.join("::"));
                return self.finding(path.span(), what, "GpuContext::wait_for");
            }
            if let Some((name, instead)) = HELPERS.iter().find(|(h, _)| resolved.iter().any(|s| s == h))
                && resolved.first().is_some_and(|s| s == "wgpu")
            {
                return self.finding(
                    path.span(),
                    format!("wgpu's `{name}` (it creates buffers of its own)"),
                    instead,
                );
            }
        }
        if raw.len() >= 2
            && let Some((_, instead)) = DIRECT.iter().find(|(d, _)| raw.last().is_some_and(|l| l == d))
        {
            let owner = &raw[..raw.len() - 1];
            let trait_ext = self.imports.resolve(owner).iter().any(|p| ends_with(p, &["util", "DeviceExt"]));
            if trait_ext || self.known.is_device_path(self.imports, owner, &self.generics()) {
                self.finding(path.span(), format!("`{}` called through its path", raw.join("::")), instead);
            }
        }
    }

    /// Macro arguments: as expressions where they parse, else searched for the method names.
    fn check_macro(&mut self, mac: &syn::Macro) {
        let parser = Punctuated::<Expr, syn::Token![,]>::parse_terminated;
        match mac.parse_body_with(parser) {
            Ok(exprs) => exprs.iter().for_each(|e| self.visit_expr(e)),
            Err(_) => self.search_tokens(mac.tokens.clone()),
        }
    }

    fn search_tokens(&mut self, tokens: TokenStream) {
        let mut after_dot = false;
        for t in tokens {
            match t {
                TokenTree::Group(g) => self.search_tokens(g.stream()),
                TokenTree::Punct(p) => after_dot = p.as_char() == '.' || p.as_char() == ':',
                TokenTree::Ident(i) => {
                    let name = i.to_string();
                    let direct = DIRECT.iter().find(|(d, _)| after_dot && *d == name);
                    if let Some((_, instead)) = direct {
                        let what = format!("`{name}` in macro tokens the check cannot read as code");
                        self.finding(i.span(), what, instead);
                    } else if name == "PollType" || HELPERS.iter().any(|(h, _)| *h == name) {
                        let what = format!("`{name}` in macro tokens the check cannot read as code");
                        self.finding(i.span(), what, "GpuContext's methods");
                    }
                    after_dot = false;
                }
                TokenTree::Literal(_) => after_dot = false,
            }
        }
    }
}

impl Visit<'_> for Finder<'_> {
    fn visit_item_impl(&mut self, i: &syn::ItemImpl) {
        let name = match &*i.self_ty {
            Type::Path(p) => p.path.segments.last().map(|s| s.ident.to_string()),
            _ => None,
        };
        if self.file.ends_with(CONTEXT_FILE) && name.as_deref() == Some("GpuContext") && i.trait_.is_none() {
            return;
        }
        let mut generics = HashSet::new();
        self.known.device_generics(self.imports, &i.generics, &mut generics);
        let device = self.known.mentions_device(self.imports, &i.self_ty, &generics);
        if device {
            generics.insert("Self".into());
        }
        self.generics.push(generics);
        self.self_device.push(device);
        visit::visit_item_impl(self, i);
        self.self_device.pop();
        self.generics.pop();
    }

    fn visit_item_trait(&mut self, t: &syn::ItemTrait) {
        let device = self.known.traits.contains(&t.ident.to_string());
        self.self_device.push(device);
        self.generics.push(if device { HashSet::from(["Self".to_string()]) } else { HashSet::new() });
        visit::visit_item_trait(self, t);
        self.generics.pop();
        self.self_device.pop();
    }

    fn visit_item_fn(&mut self, f: &syn::ItemFn) {
        self.self_device.push(false);
        self.function(&f.sig, Some(&f.block));
        self.self_device.pop();
    }

    fn visit_impl_item_fn(&mut self, f: &syn::ImplItemFn) {
        self.function(&f.sig, Some(&f.block));
    }

    fn visit_trait_item_fn(&mut self, f: &syn::TraitItemFn) {
        self.function(&f.sig, f.default.as_ref());
    }

    fn visit_block(&mut self, b: &syn::Block) {
        self.scopes.push(HashMap::new());
        visit::visit_block(self, b);
        self.scopes.pop();
    }

    fn visit_local(&mut self, l: &syn::Local) {
        if let Some(init) = &l.init {
            self.visit_expr(&init.expr);
            if let Some((_, diverge)) = &init.diverge {
                self.visit_expr(diverge);
            }
        }
        self.visit_pat(&l.pat);
        self.bind_init(&l.pat, l.init.as_ref().map(|i| &*i.expr));
    }

    fn visit_expr_let(&mut self, l: &syn::ExprLet) {
        self.visit_expr(&l.expr);
        self.visit_pat(&l.pat);
        self.bind_init(&l.pat, Some(&l.expr));
    }

    fn visit_expr_match(&mut self, m: &syn::ExprMatch) {
        self.visit_expr(&m.expr);
        let device = self.is_device(&m.expr);
        for arm in &m.arms {
            self.scopes.push(HashMap::new());
            self.visit_pat(&arm.pat);
            self.bind(&arm.pat, device);
            if let Some((_, guard)) = &arm.guard {
                self.visit_expr(guard);
            }
            self.visit_expr(&arm.body);
            self.scopes.pop();
        }
    }

    fn visit_expr_for_loop(&mut self, f: &syn::ExprForLoop) {
        self.visit_expr(&f.expr);
        self.scopes.push(HashMap::new());
        self.visit_pat(&f.pat);
        let device = self.contains_device(&f.expr);
        self.bind(&f.pat, device);
        self.visit_block(&f.body);
        self.scopes.pop();
    }

    fn visit_expr_closure(&mut self, c: &syn::ExprClosure) {
        self.scopes.push(HashMap::new());
        let fed = self.fed_device;
        for input in &c.inputs {
            // A closure parameter without a type takes what the call feeds it.
            let typed = matches!(input, Pat::Type(_));
            self.bind(input, fed && !typed);
        }
        self.fed_device = false;
        self.visit_expr(&c.body);
        self.scopes.pop();
    }

    fn visit_expr_method_call(&mut self, m: &syn::ExprMethodCall) {
        let name = m.method.to_string();
        if let Some((_, instead)) = DIRECT.iter().find(|(d, _)| *d == name)
            && self.is_device(&m.receiver)
            && !(name == "poll" && self.polls_without_waiting(&m.args))
        {
            self.finding(m.method.span(), format!("`.{name}(…)` on wgpu's device or queue"), instead);
        }
        self.visit_expr(&m.receiver);
        let fed = self.contains_device(&m.receiver) || m.args.iter().any(|a| self.contains_device(a));
        self.arguments(fed, m.args.iter());
    }

    fn visit_expr_call(&mut self, c: &syn::ExprCall) {
        self.visit_expr(&c.func);
        let fed = c.args.iter().any(|a| self.contains_device(a));
        self.arguments(fed, c.args.iter());
    }

    fn visit_expr_path(&mut self, p: &syn::ExprPath) {
        if let Some(qself) = &p.qself
            && let Some((name, instead)) =
                DIRECT.iter().find(|(d, _)| p.path.segments.last().is_some_and(|s| s.ident == d))
        {
            let trait_path: Segments = segments(&p.path).into_iter().take(qself.position).collect();
            let trait_ext =
                self.imports.resolve(&trait_path).iter().any(|t| ends_with(t, &["util", "DeviceExt"]));
            if trait_ext || self.type_is_device(&qself.ty) {
                self.finding(p.span(), format!("`<…>::{name}` called through its path"), instead);
                // Reported once: the path after the `<…>` is the same call.
                return self.visit_type(&qself.ty);
            }
        }
        visit::visit_expr_path(self, p);
    }

    fn visit_path(&mut self, path: &syn::Path) {
        self.check_path(path);
        visit::visit_path(self, path);
    }

    fn visit_macro(&mut self, mac: &syn::Macro) {
        self.check_macro(mac);
    }

    fn visit_item(&mut self, item: &Item) {
        // `use` items are read by `Imports`; the names they bring are checked where used.
        if !matches!(item, Item::Use(_)) {
            visit::visit_item(self, item);
        }
    }
}

/// The direct calls in `sources` (a display name, ending like the file's path, and its text):
/// one line each, `file:line: what, use instead`. A file that does not parse is a finding too.
pub fn find(sources: &[(String, String)]) -> Vec<String> {
    let mut findings = Vec::new();
    let mut files = Vec::new();
    for (name, text) in sources {
        match syn::parse_file(text) {
            Ok(file) => {
                let imports = Imports::of(&file);
                files.push((name.clone(), file, imports));
            }
            Err(e) => findings.push(format!("{name}: does not parse: {e}")),
        }
    }
    let known = Known::of(&files);
    for (name, file, imports) in &files {
        let mut finder = Finder {
            file: name,
            known: &known,
            imports,
            scopes: vec![HashMap::new()],
            generics: vec![HashSet::new()],
            self_device: vec![false],
            fed_device: false,
            findings: Vec::new(),
        };
        finder.visit_file(file);
        findings.extend(finder.findings);
    }
    findings
}
