//! Layering check: the file-level import graph of `core` and of the `host`
//! library must have no cycles, and no file may import a file of a folder on a
//! higher floor (tables below). The binary (host/src/cli/main.rs) is checked for
//! cycles only.
//!
//! Run: `cargo test -p treelet-tests --test layering`. `TREELET_ROOT=<dir>`
//! checks another workspace copy; `LAYERING_EDGES=1 ... -- --nocapture` prints
//! every edge found.
//!
//! How a reference is found: every path that starts with `crate`, `self`,
//! `super` (or with the name of a child module, which is `self::child`), in
//! `use` trees, in code and types, inside inline modules, and, by a token scan,
//! inside macro bodies. It is resolved to the longest prefix that is a module
//! file; that file is the edge's target.

use proc_macro2::{Spacing, TokenStream, TokenTree};
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet, VecDeque};
use std::path::{Path, PathBuf};
use syn::visit::{self, Visit};

/// Floors of core's top-level folders (`core/src/<folder>/`); a file may import files of its floor or lower.
const CORE_FLOORS: &[(&str, u32)] =
    &[("gpu", 0), ("geometry", 1), ("construct", 2), ("layouts", 3), ("trace", 4), ("render", 5), ("registry", 6)];

/// Floors of the host library's top-level folders; a top-level file (`tracer.rs`) is a folder named by its stem.
/// The engine API (`tracer`) sits below the renderer, which traces a scene's
/// instances of meshes through its `InstancedTracer`.
const HOST_LIB_FLOORS: &[(&str, u32)] =
    &[("error", 0), ("internals", 0), ("tuning", 0), ("runtime", 0), ("scene", 1), ("bvh", 2), ("tracer", 3), ("render", 4)];

/// The crate roots checked, relative to the workspace root.
const CRATES: &[CrateSpec] = &[
    CrateSpec { root: "core/src/lib.rs", floors: Some(("CORE_FLOORS", CORE_FLOORS)), root_reexports: true },
    CrateSpec { root: "host/src/lib.rs", floors: Some(("HOST_LIB_FLOORS", HOST_LIB_FLOORS)), root_reexports: true },
    // The binary is a separate crate over the same folder: its modules are the ones main.rs
    // declares (`mod bench;`); `treelet::...` paths go to the library and are not edges here.
    CrateSpec { root: "host/src/cli/main.rs", floors: None, root_reexports: false },
];

struct CrateSpec {
    /// Crate root file, relative to the workspace root.
    root: &'static str,
    /// (table name for messages, floors); `None`: cycles only.
    floors: Option<(&'static str, &'static [(&'static str, u32)])>,
    /// Report `crate::Name` that only reaches the root (a re-export) from other files.
    root_reexports: bool,
}

/// A module path below the crate root: `crate::a::b` is `["a", "b"]`, the root is `[]`.
type Mod = Vec<String>;

struct File {
    rel: String, // path shown in messages, relative to the workspace root
    module: Mod,
    ast: syn::File,
}

struct Crate {
    files: Vec<File>,            // sorted by path, so output is stable
    by_mod: HashMap<Mod, usize>, // module file -> index in `files`
    mods: HashSet<Mod>,          // every module, file-backed or inline
}

/// Follows `mod x;` declarations from the root, as rustc does, so that only the
/// crate's own files are modules (the library and the binary share host/src/).
fn load(ws: &Path, spec: &CrateSpec, errs: &mut Vec<String>) -> Crate {
    let mut files = Vec::new();
    let mut mods = HashSet::from([Mod::new()]);
    let mut queue = vec![(ws.join(spec.root), Mod::new())];
    while let Some((path, module)) = queue.pop() {
        let rel = path.strip_prefix(ws).unwrap_or(&path).display().to_string();
        let src =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("layering: cannot read {}: {e}", path.display()));
        let parsed =
            syn::parse_file(&src).map_err(|e| errs.push(format!("[parse] {rel}:{}: {e}", e.span().start().line)));
        let Ok(ast) = parsed else { continue };
        // `mod x;` in lib.rs, main.rs or foo/mod.rs lives beside it; in foo.rs it lives in foo/.
        let (parent, beside) = (path.parent().unwrap(), module.is_empty() || path.ends_with("mod.rs"));
        let dir = if beside { parent.to_path_buf() } else { parent.join(path.file_stem().unwrap()) };
        find_mods(&ast.items, &dir, &module, &rel, &mut mods, &mut queue, errs);
        files.push(File { rel, module, ast });
    }
    files.sort_by(|a, b| a.rel.cmp(&b.rel));
    let by_mod = files.iter().enumerate().map(|(i, f)| (f.module.clone(), i)).collect();
    Crate { files, by_mod, mods }
}

fn find_mods(
    items: &[syn::Item],
    dir: &Path,
    module: &Mod,
    rel: &str,
    mods: &mut HashSet<Mod>,
    queue: &mut Vec<(PathBuf, Mod)>,
    errs: &mut Vec<String>,
) {
    for item in items {
        let syn::Item::Mod(m) = item else { continue };
        let name = m.ident.to_string();
        let child: Mod = module.iter().cloned().chain([name.clone()]).collect();
        mods.insert(child.clone());
        let line = m.ident.span().start().line;
        if m.attrs.iter().any(|a| a.path().is_ident("path")) {
            // Rare, and its resolution rules are subtle: fail loudly rather than guess.
            errs.push(format!("[unsupported] {rel}:{line}: `#[path]` on `mod {name}`: teach tests/layering.rs"));
        } else if let Some((_, inner)) = &m.content {
            find_mods(inner, &dir.join(&name), &child, rel, mods, queue, errs);
        } else {
            match [dir.join(format!("{name}.rs")), dir.join(&name).join("mod.rs")].into_iter().find(|p| p.is_file()) {
                Some(p) => queue.push((p, child)),
                None => errs.push(format!("[missing] {rel}:{line}: no file for `mod {name};`")),
            }
        }
    }
}

/// Collects the crate-internal paths of one file: (line, text as written, absolute module path).
struct Collector<'a> {
    mods: &'a HashSet<Mod>,
    module: Mod, // the file's module plus the inline modules we are inside
    refs: Vec<(usize, String, Mod)>,
}

impl Collector<'_> {
    fn record(&mut self, segs: &[String], line: usize, text: String) {
        // `self.module` includes inline modules, so `super` in `mod tests` of crate::a::b is crate::a::b.
        let (mut base, mut rest) = match segs.first().map(String::as_str) {
            Some("crate") => (Mod::new(), &segs[1..]),
            Some("self") => (self.module.clone(), &segs[1..]),
            Some("super") => (self.module.clone(), segs),
            // Since edition 2018 `child::x` is `self::child::x`.
            Some(first) if self.mods.contains(&[&self.module[..], &[first.to_string()]].concat()) => {
                (self.module.clone(), segs)
            }
            _ => return,
        };
        while rest.first().map(String::as_str) == Some("super") {
            if base.pop().is_none() {
                return; // above the crate root: not ours to judge (rustc will)
            }
            rest = &rest[1..];
        }
        base.extend(rest.iter().cloned());
        self.refs.push((line, text, base));
    }

    fn use_tree(&mut self, tree: &syn::UseTree, pre: &mut Vec<String>) {
        use syn::UseTree::*;
        match tree {
            Path(p) => {
                pre.push(p.ident.to_string());
                self.use_tree(&p.tree, pre);
                pre.pop();
            }
            Name(syn::UseName { ident }) | Rename(syn::UseRename { ident, .. }) => {
                let mut segs = pre.clone();
                if ident != "self" {
                    segs.push(ident.to_string()); // `a::{self}` is `a`
                }
                self.record(&segs, ident.span().start().line, segs.join("::"));
            }
            Glob(g) => self.record(pre, g.star_token.spans[0].start().line, format!("{}::*", pre.join("::"))),
            Group(g) => g.items.iter().for_each(|t| self.use_tree(t, pre)),
        }
    }

    /// Macro bodies are raw tokens: pick out runs like `crate::a::b`, `$crate::a`, `super::x`.
    fn scan(&mut self, tokens: TokenStream) {
        let toks: Vec<TokenTree> = tokens.into_iter().collect();
        let colons = |j: usize| {
            matches!((toks.get(j), toks.get(j + 1)), (Some(TokenTree::Punct(a)), Some(TokenTree::Punct(b)))
                if a.as_char() == ':' && a.spacing() == Spacing::Joint && b.as_char() == ':')
        };
        let mut i = 0;
        while i < toks.len() {
            match &toks[i] {
                TokenTree::Group(g) => self.scan(g.stream()),
                TokenTree::Ident(id) if ["crate", "super", "self"].contains(&id.to_string().as_str()) => {
                    let mut segs = vec![id.to_string()];
                    while let (true, Some(TokenTree::Ident(next))) = (colons(i + 1), toks.get(i + 3)) {
                        segs.push(next.to_string());
                        i += 3;
                    }
                    // `$crate::name!(..)`: a `#[macro_export]` macro, which Rust puts at the
                    // crate root whatever file defines it; its only path, so no edge.
                    if matches!(toks.get(i + 1), Some(TokenTree::Punct(p)) if p.as_char() == '!') {
                        i += 1;
                        continue;
                    }
                    let open_end = colons(i + 1); // `crate::{..}`, `super::*`, `x::<T>`
                                                  // A bare `self` is a receiver; `crate::{..}` alone would wrongly look like a root re-export.
                    if segs.len() > 1 || (open_end && segs[0] != "crate") {
                        self.record(&segs, id.span().start().line, segs.join("::"));
                    }
                }
                _ => {}
            }
            i += 1;
        }
    }
}

impl<'ast> Visit<'ast> for Collector<'_> {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if let Some((_, items)) = &m.content {
            self.module.push(m.ident.to_string());
            items.iter().for_each(|item| self.visit_item(item));
            self.module.pop();
        }
    }
    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        if u.leading_colon.is_none() {
            self.use_tree(&u.tree, &mut Vec::new());
        }
    }
    fn visit_path(&mut self, p: &'ast syn::Path) {
        // One segment is a local name (a variable may share a module's name), never a module path.
        if p.leading_colon.is_none() && p.segments.len() > 1 {
            let segs: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
            self.record(&segs, p.segments[0].ident.span().start().line, segs.join("::"));
        }
        visit::visit_path(self, p); // generic arguments hold paths too
    }
    // `pub(in crate::x)` and attributes name paths without depending on them.
    fn visit_vis_restricted(&mut self, _: &'ast syn::VisRestricted) {}
    fn visit_attribute(&mut self, _: &'ast syn::Attribute) {}
    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        self.visit_path(&m.path);
        self.scan(m.tokens.clone());
    }
}

/// All violations in the given crates of the workspace at `ws`; empty means clean.
fn check(ws: &Path, specs: &[CrateSpec]) -> Vec<String> {
    let mut out = Vec::new();
    specs.iter().for_each(|spec| check_crate(ws, spec, &mut out));
    out
}

fn check_crate(ws: &Path, spec: &CrateSpec, out: &mut Vec<String>) {
    let c = load(ws, spec, out);
    let Some(&root) = c.by_mod.get(&Mod::new()) else { return }; // root did not parse: reported
                                                                 // (from, to) -> (line, text, count) of the first reference.
    let mut edges: BTreeMap<(usize, usize), (usize, String, usize)> = BTreeMap::new();
    for (from, f) in c.files.iter().enumerate() {
        let mut col = Collector { mods: &c.mods, module: f.module.clone(), refs: Vec::new() };
        col.visit_file(&f.ast);
        for (line, text, abs) in col.refs {
            let to = (0..=abs.len()).rev().find_map(|n| c.by_mod.get(&abs[..n])).copied().unwrap_or(root);
            // Only the root reached, and not through an inline module of the root: a re-export.
            let inline_root_mod = abs.get(..1).is_some_and(|top| c.mods.contains(top));
            if spec.root_reexports && to == root && from != root && !inline_root_mod {
                let msg = format!(
                    "[root re-export] {}:{line}: `{text}` goes through the crate root ({}); import it from the module that defines it",
                    f.rel, spec.root
                );
                if !out.contains(&msg) {
                    out.push(msg); // once per line
                }
            }
            if from != to {
                edges.entry((from, to)).or_insert((line, text, 0)).2 += 1;
            }
        }
    }
    let witness = |a: usize, b: usize| {
        let (line, text, n) = &edges[&(a, b)];
        let more = if *n > 1 { format!(" (+{} more)", n - 1) } else { String::new() };
        format!("{}:{line}: `{text}`{more}", c.files[a].rel)
    };
    if std::env::var_os("LAYERING_EDGES").is_some() {
        eprintln!("== edges of {} ==", spec.root);
        for &(a, b) in edges.keys() {
            eprintln!("{:<40} -> {:<40} {}", c.files[a].rel, c.files[b].rel, witness(a, b));
        }
    }

    if let Some((table, floors)) = spec.floors {
        // Top-level folder (first module segment) of each file; the root has none and is exempt.
        let mut tops: BTreeMap<&str, &str> = BTreeMap::new();
        for f in &c.files {
            if let Some(top) = f.module.first() {
                tops.entry(top).or_insert(&f.rel);
            }
        }
        for (top, rel) in &tops {
            if !floors.iter().any(|(n, _)| n == top) {
                out.push(format!("[unassigned folder] `{top}` (e.g. {rel}) has no floor in {table}: add it"));
            }
        }
        let floor = |i: usize| {
            let top = c.files[i].module.first()?;
            floors.iter().find(|(n, _)| n == top).map(|&(n, r)| (n, r))
        };
        for &(a, b) in edges.keys() {
            if let (Some((fa, ra)), Some((fb, rb))) = (floor(a), floor(b)) {
                if ra < rb {
                    out.push(format!(
                        "[floor] {} -> {}: `{fa}` (floor {ra}) must not import `{fb}` (floor {rb}); move the item down or invert the dependency ({table})",
                        witness(a, b),
                        c.files[b].rel
                    ));
                }
            }
        }
    }

    // Cycles: the shortest cycle through each file (any cycle stays inside one tangle, so
    // this names every file of every tangle), deduplicated.
    let mut adj = vec![Vec::new(); c.files.len()];
    for &(a, b) in edges.keys() {
        adj[a].push(b);
    }
    let cycles: BTreeSet<Vec<usize>> = (0..adj.len()).filter_map(|v| shortest_cycle(&adj, v)).collect();
    for cy in cycles {
        let names: Vec<&str> = cy.iter().chain([&cy[0]]).map(|&i| c.files[i].rel.as_str()).collect();
        let mut msg = format!("[cycle] {}", names.join(" -> "));
        for k in 0..cy.len() {
            msg += &format!("\n        {}", witness(cy[k], cy[(k + 1) % cy.len()]));
        }
        out.push(msg);
    }
}

/// Shortest cycle through `v` (BFS), rotated to start at its smallest node so duplicates merge.
fn shortest_cycle(adj: &[Vec<usize>], v: usize) -> Option<Vec<usize>> {
    let mut prev: Vec<Option<usize>> = vec![None; adj.len()];
    let mut queue = VecDeque::from([v]);
    while let Some(u) = queue.pop_front() {
        for &w in &adj[u] {
            if w == v {
                let mut cy = vec![u];
                while *cy.last().unwrap() != v {
                    cy.push(prev[*cy.last().unwrap()].unwrap());
                }
                cy.reverse();
                let k = (0..cy.len()).min_by_key(|&k| cy[k]).unwrap();
                cy.rotate_left(k);
                return Some(cy);
            }
            if prev[w].is_none() {
                prev[w] = Some(u);
                queue.push_back(w);
            }
        }
    }
    None
}

#[test]
fn workspace_layering() {
    let ws = std::env::var("TREELET_ROOT").unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/..").to_string());
    let v = check(Path::new(&ws), CRATES);
    assert!(
        v.is_empty(),
        "\nlayering: {} violation(s) in {ws} (rules and floor tables: tests/layering.rs)\n\n{}\n",
        v.len(),
        v.join("\n")
    );
}

// ---- self-tests on tiny synthetic trees ----

const TEST_FLOORS: &[(&str, u32)] = &[("low", 0), ("high", 1)];
const TEST_CRATE: &[CrateSpec] =
    &[CrateSpec { root: "src/lib.rs", floors: Some(("TEST_FLOORS", TEST_FLOORS)), root_reexports: true }];

/// Writes `files` under a fresh temp dir, runs the checker on it, removes the dir.
fn check_tree(name: &str, files: &[(&str, &str)]) -> Vec<String> {
    let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().as_nanos();
    let dir = std::env::temp_dir().join(format!("layering-{name}-{}-{nanos}", std::process::id()));
    for (path, src) in files {
        let path = dir.join(path);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, src).unwrap();
    }
    let v = check(&dir, TEST_CRATE);
    let _ = std::fs::remove_dir_all(&dir);
    v
}

#[test]
fn reports_cycle() {
    // a -> b only inside a macro; b -> a only from an inline test module (`super::super` is the root).
    let v = check_tree(
        "cycle",
        &[
            ("src/lib.rs", "mod low;\npub use low::a::Y;"),
            ("src/low/mod.rs", "pub mod a; mod b;"),
            ("src/low/a.rs", "pub struct Y;\nfn f() { let _ = vec![crate::low::b::X]; }\nfn g(_: crate::Y) {}"),
            ("src/low/b.rs", "pub struct X;\n#[cfg(test)]\nmod tests {\n    use super::super::a::Y;\n}"),
        ],
    );
    let cycle = v
        .iter()
        .find(|m| m.starts_with("[cycle] src/low/a.rs"))
        .unwrap_or_else(|| panic!("no a <-> b cycle in {v:#?}"));
    assert!(cycle.contains("src/low/a.rs -> src/low/b.rs -> src/low/a.rs"), "{cycle}");
    assert!(
        cycle.contains("src/low/a.rs:2: `crate::low::b::X`") && cycle.contains("src/low/b.rs:4: `super::super::a::Y`"),
        "{cycle}"
    );
    // The root is a node like any other: `crate::Y` in a.rs closes a cycle through lib.rs's re-export.
    assert!(v.iter().any(|m| m.starts_with("[cycle] src/lib.rs -> src/low/a.rs -> src/lib.rs")), "{v:#?}");
    assert!(v.iter().any(|m| m.starts_with("[root re-export] src/low/a.rs:3: `crate::Y`")), "{v:#?}");
}

/// A macro a macro body calls through `$crate::name!` lives at the root by
/// Rust's rule (`#[macro_export]`): not a re-export to report.
#[test]
fn exported_macros_are_named_from_the_root() {
    let v = check_tree(
        "macros",
        &[
            ("src/lib.rs", "mod low;"),
            ("src/low/mod.rs", "#[macro_export]\nmacro_rules! a { () => { $crate::b!() }; }\n#[macro_export]\nmacro_rules! b { () => {}; }"),
        ],
    );
    assert!(v.is_empty(), "{v:#?}");
}

#[test]
fn reports_floor_violation() {
    let v = check_tree(
        "floor",
        &[
            ("src/lib.rs", "mod low; mod high;"),
            ("src/low/mod.rs", "mod x;"),
            ("src/low/x.rs", "fn f() {\n    crate::high::g();\n}"),
            ("src/high.rs", "pub fn g() {}"),
        ],
    );
    assert_eq!(v.len(), 1, "{v:#?}");
    assert!(
        v[0].starts_with("[floor] src/low/x.rs:2: `crate::high::g`")
            && v[0].contains("`low` (floor 0) must not import `high` (floor 1)"),
        "{v:#?}"
    );
}

#[test]
fn clean_tree_passes() {
    let v = check_tree("clean", &[
        ("src/lib.rs", "mod low; mod high;\npub use low::x::Thing;"),
        ("src/low/mod.rs", "pub mod x;\npub mod y;\npub use x::Thing;"),
        ("src/low/x.rs", "pub struct Thing;\nuse super::y::{self, Other as O};\n#[cfg(test)]\nmod tests { use super::*; }"),
        ("src/low/y.rs", "pub struct Other; pub(in crate::low) fn h() {}"),
        ("src/high.rs", "use crate::low::{x::{self, Thing}, y::*};\nfn f() -> Thing { let scene = 1; let _ = scene; crate::low::x::Thing }"),
    ]);
    assert!(v.is_empty(), "{v:#?}");
}
