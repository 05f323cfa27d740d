//! The renderer's modules form layers (docs/architecture.md): each uses only its own layer and the
//! layers below, shading never reads the scene description, and no module uses another that uses it
//! back. Checked from the source of `src/`: every `use` declaration and every `crate::`, `super::`,
//! `self::` or child-module path outside comments and strings is resolved (through `pub use`
//! re-exports, globs included) to the module that defines the item. In-file `#[cfg(test)]` modules are
//! left out: a test may build its fixtures with any layer. Re-exports (`pub use`) are a module's
//! public face, not a dependency of its code, and are not edges either.
//!
//! Two checks: among the children of every module (the top-level modules under the crate root, the
//! submodules of `scene`, of `mesh_io`...) the "uses" graph has no cycle; and every edge between the
//! layer nodes of [`LAYERS`] goes to the same layer or a lower one. A self-test plants the violations
//! the rules exist for and requires both checks to see them.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Layer of each top-level module, and of each submodule of `scene` (the description, the readers, the
/// runtime scene and the build step share that folder). Lower numbers are lower layers.
const LAYERS: &[(&str, u32)] = &[
    // Foundations: vectors, errors, reading input files, images, meshes, sampling, exact sums.
    ("math", 0),
    ("error", 0),
    ("film", 0),
    ("sampler", 0),
    ("accum", 0),
    ("image_io", 0),
    ("mesh_io", 0),
    ("input", 0),
    ("tonemap", 0),
    ("renderer", 0),
    // The description: plain data with source positions, and its limits.
    ("scene::desc", 1),
    ("scene::limits", 1),
    // The readers: scene file -> description.
    ("scene::readers", 2),
    // `scene/mod.rs` itself: re-exports only, which are not dependencies.
    ("scene", 2),
    // The runtime scene: geometry over arbor-accel, materials, lights, cameras, settings.
    ("camera", 3),
    ("light", 3),
    ("material", 3),
    ("texture", 3),
    ("scene::geometry", 3),
    ("scene::clearance", 3),
    ("scene::runtime", 3),
    // The build step: description -> runtime scene, loading assets.
    ("scene::build", 4),
    // Shading and rendering: runtime types only.
    ("integrator", 5),
    ("render", 6),
    // Tools over whole renders.
    ("farm", 7),
    ("bench", 7),
];

type ModPath = Vec<String>;

/// First segment of a path into another crate (never a module name).
const EXTERN: &str = "::";

/// One source file: the module it is, its code without comments, strings and in-file tests.
struct File {
    module: ModPath,
    name: String,
    code: String,
    /// Child modules declared in it (`mod x;`).
    children: Vec<String>,
}

/// A path one file names, with the line it is on.
struct Ref {
    path: ModPath,
    line: usize,
}

struct Crate {
    files: Vec<File>,
    modules: BTreeSet<ModPath>,
    /// Per module: name -> absolute path it re-exports (`pub use`), and glob re-export sources.
    reexports: BTreeMap<ModPath, BTreeMap<String, ModPath>>,
    globs: BTreeMap<ModPath, Vec<ModPath>>,
    /// Per module: names of the public items it defines.
    items: BTreeMap<ModPath, BTreeSet<String>>,
}

fn module_of(rel: &str) -> ModPath {
    let rel = rel.trim_end_matches(".rs");
    let mut parts: ModPath = rel.split('/').map(str::to_string).collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib" | "main")) && parts.len() == 1
        || parts.last().is_some_and(|p| p == "mod")
    {
        parts.pop();
    }
    parts
}

/// The code with comments, string and char literals blanked (newlines kept, for line numbers).
fn strip(src: &str) -> String {
    let c: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(src.len());
    let blank = |out: &mut String, ch: char| out.push(if ch == '\n' { '\n' } else { ' ' });
    let mut i = 0;
    let ident = |k: usize| k > 0 && (c[k - 1].is_alphanumeric() || c[k - 1] == '_');
    while i < c.len() {
        if c[i] == '/' && c.get(i + 1) == Some(&'/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if c[i] == '/' && c.get(i + 1) == Some(&'*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    blank(&mut out, c[i]);
                    i += 1;
                }
            }
        } else if c[i] == 'r' && !ident(i) && matches!(c.get(i + 1), Some('"' | '#')) {
            let mut j = i + 1;
            while c.get(j) == Some(&'#') {
                j += 1;
            }
            if c.get(j) != Some(&'"') {
                out.push(c[i]);
                i += 1;
                continue;
            }
            let hashes = j - i - 1;
            i = j + 1;
            while i < c.len() && !(c[i] == '"' && (0..hashes).all(|h| c.get(i + 1 + h) == Some(&'#'))) {
                blank(&mut out, c[i]);
                i += 1;
            }
            i += 1 + hashes;
        } else if c[i] == '"' {
            i += 1;
            while i < c.len() && c[i] != '"' {
                blank(&mut out, c[i]);
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
        } else if c[i] == '\'' && (c.get(i + 1) == Some(&'\\') || c.get(i + 2) == Some(&'\'')) {
            i += 1;
            while i < c.len() && c[i] != '\'' {
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// The code without `#[cfg(test)] mod NAME { ... }` blocks.
fn drop_test_modules(code: &str) -> String {
    let mut out = code.to_string();
    while let Some(at) = out.find("#[cfg(test)]") {
        let rest = &out[at..];
        let Some(open) = rest.find('{') else { break };
        let is_mod = rest[..open].split_whitespace().any(|w| w == "mod");
        let mut depth = 0;
        let mut end = rest.len();
        for (k, ch) in rest.char_indices().skip(open) {
            match ch {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = k + 1;
                        break;
                    }
                }
                _ => {}
            }
        }
        let keep: String = rest[..end].chars().map(|ch| if ch == '\n' { '\n' } else { ' ' }).collect();
        let replacement = if is_mod { keep } else { rest[..end].replacen("#[cfg(test)]", "            ", 1) };
        out.replace_range(at..at + end, &replacement);
    }
    out
}

fn is_ident(ch: char) -> bool {
    ch.is_alphanumeric() || ch == '_'
}

/// The paths a `use` tree names, with `{...}` expanded and `self` folded into its prefix; `as` aliases
/// are returned beside the path (the name it is known by).
fn expand_tree(prefix: &ModPath, tree: &str, out: &mut Vec<(ModPath, String)>) {
    let tree = tree.trim();
    if let Some(open) = tree.find('{') {
        let head: ModPath =
            tree[..open].split("::").map(str::trim).filter(|s| !s.is_empty()).map(str::to_string).collect();
        let base: ModPath = prefix.iter().cloned().chain(head).collect();
        let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
        let (mut depth, mut start) = (0, 0);
        for (k, ch) in inner.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand_tree(&base, &inner[start..k], out);
                    start = k + 1;
                }
                _ => {}
            }
        }
        expand_tree(&base, &inner[start..], out);
        return;
    }
    if tree.is_empty() {
        return;
    }
    let (path, alias) = match tree.split_once(" as ") {
        Some((p, a)) => (p.trim(), Some(a.trim().to_string())),
        None => (tree, None),
    };
    let mut full: ModPath = prefix.clone();
    full.extend(path.split("::").map(str::trim).filter(|s| !s.is_empty()).map(str::to_string));
    if full.last().map(String::as_str) == Some("self") {
        full.pop();
    }
    let name = alias.unwrap_or_else(|| full.last().cloned().unwrap_or_default());
    out.push((full, name));
}

/// One `use` declaration.
struct UseDecl {
    /// `pub use` (any visibility): a re-export.
    public: bool,
    /// The paths it names, each with the name it is known by.
    paths: Vec<(ModPath, String)>,
    line: usize,
}

/// `use` declarations of `code`.
fn use_decls(code: &str) -> Vec<UseDecl> {
    let mut out = Vec::new();
    let text = code;
    let mut search = 0;
    while let Some(k) = text[search..].find("use ") {
        let at = search + k;
        search = at + 4;
        if at > 0 && is_ident(text[..at].chars().last().unwrap()) {
            continue;
        }
        let before = text[..at].trim_end();
        let is_pub = before.ends_with("pub")
            || (before.ends_with(')') && before[..before.rfind('(').unwrap_or(0)].trim_end().ends_with("pub"));
        let Some(end) = text[at..].find(';') else { break };
        let mut paths = Vec::new();
        expand_tree(&Vec::new(), &text[at + 4..at + end], &mut paths);
        out.push(UseDecl { public: is_pub, paths, line: text[..at].matches('\n').count() + 1 });
    }
    out
}

/// The code with its `use` declarations blanked.
fn without_uses(code: &str) -> String {
    let mut out = code.to_string();
    let mut search = 0;
    while let Some(k) = out[search..].find("use ") {
        let at = search + k;
        search = at + 4;
        if at > 0 && is_ident(out[..at].chars().last().unwrap()) {
            continue;
        }
        let Some(end) = out[at..].find(';') else { break };
        let blank: String = out[at..at + end].chars().map(|ch| if ch == '\n' { '\n' } else { ' ' }).collect();
        out.replace_range(at..at + end, &blank);
    }
    out
}

/// Paths in code (outside `use`) that start with `crate`, `super`, `self` or one of `children`.
fn inline_paths(code: &str, children: &[String]) -> Vec<(ModPath, usize)> {
    let chars: Vec<char> = code.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    let mut line = 1;
    while i < chars.len() {
        if chars[i] == '\n' {
            line += 1;
        }
        if is_ident(chars[i]) && (i == 0 || !(is_ident(chars[i - 1]) || chars[i - 1] == ':')) {
            let mut segs = Vec::new();
            let mut j = i;
            loop {
                let start = j;
                while j < chars.len() && is_ident(chars[j]) {
                    j += 1;
                }
                segs.push(chars[start..j].iter().collect::<String>());
                if chars.get(j) == Some(&':')
                    && chars.get(j + 1) == Some(&':')
                    && chars.get(j + 2).is_some_and(|&c| is_ident(c))
                {
                    j += 2;
                } else {
                    break;
                }
            }
            let first = segs[0].as_str();
            if segs.len() > 1 && (matches!(first, "crate" | "super" | "self") || children.iter().any(|c| c == first)) {
                out.push((segs, line));
            }
            i = j;
            continue;
        }
        i += 1;
    }
    out
}

/// Names of the public items `code` defines.
fn public_items(code: &str) -> BTreeSet<String> {
    let words: Vec<&str> = code.split(|c: char| !is_ident(c)).filter(|w| !w.is_empty()).collect();
    let mut out = BTreeSet::new();
    for (k, w) in words.iter().enumerate() {
        if *w != "pub" {
            continue;
        }
        for d in 1..5 {
            match words.get(k + d) {
                Some(&"fn" | &"struct" | &"enum" | &"trait" | &"type" | &"static" | &"mod" | &"union") => {
                    out.extend(words.get(k + d + 1).map(|s| s.to_string()));
                    break;
                }
                Some(&"const") if words.get(k + d + 1) != Some(&"fn") => {
                    out.extend(words.get(k + d + 1).map(|s| s.to_string()));
                    break;
                }
                _ => {}
            }
        }
    }
    out
}

impl Crate {
    fn from_sources(sources: &BTreeMap<String, String>) -> Crate {
        let mut files = Vec::new();
        for (rel, src) in sources {
            let code = drop_test_modules(&strip(src));
            let words: Vec<&str> = code.split(|c: char| !is_ident(c) && c != ';').filter(|w| !w.is_empty()).collect();
            let children = words
                .windows(2)
                .filter(|w| w[0] == "mod" && w[1].ends_with(';'))
                .map(|w| w[1].trim_end_matches(';').to_string())
                .collect();
            files.push(File { module: module_of(rel), name: format!("src/{rel}"), code, children });
        }
        let modules = files.iter().map(|f| f.module.clone()).collect();
        let mut c =
            Crate { files, modules, reexports: BTreeMap::new(), globs: BTreeMap::new(), items: BTreeMap::new() };
        for k in 0..c.files.len() {
            let (module, code) = (c.files[k].module.clone(), c.files[k].code.clone());
            c.items.insert(module.clone(), public_items(&code));
            for decl in use_decls(&code).into_iter().filter(|d| d.public) {
                for (path, name) in decl.paths {
                    // A re-export from another crate: marked so that resolving stops there.
                    let abs = c
                        .absolute(&c.files[k], &path)
                        .unwrap_or_else(|| [EXTERN.to_string()].into_iter().chain(path).collect());
                    if name == "*" {
                        c.globs.entry(module.clone()).or_default().push(abs[..abs.len() - 1].to_vec());
                    } else {
                        c.reexports.entry(module.clone()).or_default().insert(name, abs);
                    }
                }
            }
        }
        c
    }

    /// `path` as named in `file`, from the crate root; `None` outside the crate.
    fn absolute(&self, file: &File, path: &ModPath) -> Option<ModPath> {
        let mut segs = path.iter();
        let first = segs.next()?;
        let mut base = match first.as_str() {
            "crate" => Vec::new(),
            "self" => file.module.clone(),
            "super" => file.module[..file.module.len().checked_sub(1)?].to_vec(),
            c if file.children.iter().any(|x| x == c) => {
                let mut m = file.module.clone();
                m.push(c.to_string());
                m
            }
            _ => return None,
        };
        let mut rest: Vec<&String> = segs.collect();
        while rest.first().map(|s| s.as_str()) == Some("super") {
            base.pop();
            rest.remove(0);
        }
        base.extend(rest.into_iter().cloned());
        Some(base)
    }

    /// The module that defines what the absolute `path` names; `None` outside the crate.
    fn resolve(&self, path: &[String], depth: u32) -> Option<ModPath> {
        if depth > 16 || path.first().is_some_and(|s| s == EXTERN) {
            return None;
        }
        let mut cur: ModPath = Vec::new();
        for (k, seg) in path.iter().enumerate() {
            let mut next = cur.clone();
            next.push(seg.clone());
            if self.modules.contains(&next) {
                cur = next;
                continue;
            }
            let rest = &path[k + 1..];
            if let Some(target) = self.reexports.get(&cur).and_then(|r| r.get(seg)) {
                let full: ModPath = target.iter().chain(rest).cloned().collect();
                return self.resolve(&full, depth + 1);
            }
            for glob in self.globs.get(&cur).into_iter().flatten() {
                let defines = self.items.get(glob).is_some_and(|i| i.contains(seg));
                let reexports = self.reexports.get(glob).is_some_and(|r| r.contains_key(seg));
                if defines || reexports {
                    let full: ModPath = glob.iter().chain(std::iter::once(seg)).chain(rest).cloned().collect();
                    return self.resolve(&full, depth + 1);
                }
            }
            return Some(cur);
        }
        Some(cur)
    }

    /// Every dependency: (from module, to module, file, line).
    fn edges(&self) -> Vec<(ModPath, ModPath, String, usize)> {
        let mut out = Vec::new();
        for f in &self.files {
            let mut refs: Vec<Ref> = Vec::new();
            for decl in use_decls(&f.code).into_iter().filter(|d| !d.public) {
                refs.extend(decl.paths.into_iter().map(|(path, _)| Ref { path, line: decl.line }));
            }
            refs.extend(
                inline_paths(&without_uses(&f.code), &f.children).into_iter().map(|(path, line)| Ref { path, line }),
            );
            for r in refs {
                let Some(abs) = self.absolute(f, &r.path) else { continue };
                if let Some(to) = self.resolve(&abs, 0) {
                    if to != f.module {
                        out.push((f.module.clone(), to, f.name.clone(), r.line));
                    }
                }
            }
        }
        out
    }
}

/// Cycles among the children of each module, as messages.
fn sibling_cycles(c: &Crate) -> Vec<String> {
    // parent -> child -> (child it uses -> where).
    let mut graphs: BTreeMap<ModPath, BTreeMap<String, BTreeMap<String, String>>> = BTreeMap::new();
    for (from, to, file, line) in c.edges() {
        let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
        if common < from.len() && common < to.len() {
            let graph = graphs.entry(from[..common].to_vec()).or_default();
            let uses = graph.entry(from[common].clone()).or_default();
            uses.entry(to[common].clone()).or_insert_with(|| format!("{file}:{line}"));
        }
    }
    let mut out = Vec::new();
    let mut reported = BTreeSet::new();
    for (parent, graph) in &graphs {
        let name = |m: &str| if parent.is_empty() { m.to_string() } else { format!("{}::{m}", parent.join("::")) };
        for start in graph.keys() {
            // A path from `start` back to itself, depth first.
            let mut stack = vec![(start.clone(), vec![start.clone()])];
            let mut seen = BTreeSet::new();
            while let Some((node, trail)) = stack.pop() {
                for (next, _) in graph.get(&node).into_iter().flatten() {
                    if next == start {
                        if !reported.insert((parent.clone(), trail.iter().cloned().collect::<BTreeSet<_>>())) {
                            continue;
                        }
                        let mut steps = Vec::new();
                        let full: Vec<&String> = trail.iter().chain(std::iter::once(start)).collect();
                        for w in full.windows(2) {
                            steps.push(format!("{} uses {} ({})", name(w[0]), name(w[1]), graph[w[0]][w[1]]));
                        }
                        out.push(format!("module cycle: {}", steps.join("; ")));
                    } else if seen.insert(next.clone()) {
                        let mut t = trail.clone();
                        t.push(next.clone());
                        stack.push((next.clone(), t));
                    }
                }
            }
        }
    }
    out
}

/// The layer node of a module: a top-level module, or a submodule of `scene`.
fn layer_node(m: &ModPath) -> Option<String> {
    match m.as_slice() {
        [] => None,
        [s, sub, ..] if s == "scene" => Some(format!("scene::{sub}")),
        [top, ..] => Some(top.clone()),
    }
}

/// Layers that hold the description (its data and its readers): only the build step and the tools
/// above rendering may use them.
const DESCRIPTION: [u32; 2] = [1, 2];
/// Layers that must not use the description: the runtime scene, shading and rendering.
const RUNTIME: [u32; 3] = [3, 5, 6];

/// Uses that go up the layers, runtime modules reading the description, and modules missing in
/// [`LAYERS`], as messages.
fn layer_violations(c: &Crate) -> Vec<String> {
    let layer = |n: &str| LAYERS.iter().find(|(name, _)| *name == n).map(|&(_, l)| l);
    let mut out = BTreeSet::new();
    for m in &c.modules {
        if let Some(n) = layer_node(m).filter(|n| layer(n).is_none()) {
            out.insert(format!(
                "module {n} has no layer: add it to LAYERS in tests/module_layers.rs and docs/architecture.md"
            ));
        }
    }
    for (from, to, file, line) in c.edges() {
        let (Some(a), Some(b)) = (layer_node(&from), layer_node(&to)) else { continue };
        if let (Some(la), Some(lb)) = (layer(&a), layer(&b)) {
            if lb > la {
                out.insert(format!("{file}:{line}: {a} (layer {la}) uses {b} (layer {lb}), a higher layer"));
            }
            if RUNTIME.contains(&la) && DESCRIPTION.contains(&lb) {
                out.insert(format!(
                    "{file}:{line}: {a} (layer {la}) reads the description ({b}): only the build step may"
                ));
            }
        }
    }
    out.into_iter().collect()
}

fn sources() -> BTreeMap<String, String> {
    sources_of(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"))
}

/// Every `.rs` file below `src`, by its path relative to `src`.
fn sources_of(src: &Path) -> BTreeMap<String, String> {
    let src = src.to_path_buf();
    let mut out = BTreeMap::new();
    let mut dirs = vec![src.clone()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") && !path.ends_with("tests.rs") {
                // A `tests.rs` is a `#[cfg(test)] mod tests;`: test code, like the in-file tests left out.
                let rel = path.strip_prefix(&src).unwrap().to_string_lossy().replace('\\', "/");
                out.insert(rel, std::fs::read_to_string(&path).unwrap());
            }
        }
    }
    out
}

#[test]
fn module_layers_no_cycle_among_sibling_modules() {
    let cycles = sibling_cycles(&Crate::from_sources(&sources()));
    assert!(cycles.is_empty(), "{}", cycles.join("\n"));
}

#[test]
fn module_layers_no_cycle_in_the_other_crates_of_the_workspace() {
    for krate in ["arbor-accel", "arbor-cli"] {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(krate).join("src");
        let sources = sources_of(&src);
        assert!(sources.len() > 5, "{krate}: no sources found in {}", src.display());
        let cycles = sibling_cycles(&Crate::from_sources(&sources));
        assert!(cycles.is_empty(), "{krate}:\n{}", cycles.join("\n"));
    }
}

#[test]
fn module_layers_each_module_uses_only_its_layer_and_below() {
    let violations = layer_violations(&Crate::from_sources(&sources()));
    assert!(violations.is_empty(), "{}", violations.join("\n"));
}

#[test]
fn module_layers_resolve_through_reexports() {
    let c = Crate::from_sources(&sources());
    let resolve = |p: &str| c.resolve(&p.split("::").map(str::to_string).collect::<Vec<_>>(), 0).map(|m| m.join("::"));
    assert_eq!(resolve("scene::SceneDesc").as_deref(), Some("scene::desc"), "through the glob of desc");
    assert_eq!(resolve("scene::Scene").as_deref(), Some("scene::runtime"));
    assert_eq!(resolve("scene::SceneGeometry").as_deref(), Some("scene::geometry"));
    assert_eq!(resolve("Location").as_deref(), Some("error"));
    assert_eq!(resolve("accel::Hit"), None, "arbor-accel is outside the crate");
    let edges = c.edges();
    let uses = |from: &str, to: &str| edges.iter().any(|(a, b, _, _)| a.join("::") == from && b.join("::") == to);
    assert!(uses("integrator::whitted", "scene::runtime"));
    assert!(uses("scene::build", "scene::desc"));
    assert!(uses("scene::build", "mesh_io"), "an inline crate:: path counts");
    assert!(uses("scene::readers::metu::camera", "scene::desc"));
    assert!(uses("scene::readers", "scene::readers::xml"), "a child module's inline path counts");
    assert!(!uses("scene::limits", "scene::readers"), "in-file tests are not dependencies");
}

#[test]
fn module_layers_checks_catch_planted_violations() {
    let plant = |file: &str, line: &str| {
        let mut s = sources();
        let text = s.get_mut(file).unwrap_or_else(|| panic!("no src/{file}"));
        text.push_str(line);
        Crate::from_sources(&s)
    };
    // The description naming a runtime type: a use going up the layers (not a cycle by itself).
    let c = plant("scene/desc.rs", "\nuse crate::light::Light;\n");
    assert!(layer_violations(&c).iter().any(|v| v.contains("scene::desc (layer 1) uses light (layer 3)")));
    // A light reading the scene: a cycle between top-level modules and a use going up.
    let c = plant("light/point.rs", "\nfn f(_: &crate::scene::SceneDesc) {}\n");
    let cycles = sibling_cycles(&c);
    assert!(cycles.iter().any(|m| m.contains("light uses scene") && m.contains("scene uses light")), "{cycles:?}");
    assert!(layer_violations(&c).iter().any(|v| v.contains("light (layer 3) reads the description (scene::desc)")));
    // Shading reading the description (going down the layers, but past the build step).
    let c = plant("integrator/whitted.rs", "\nuse crate::scene::MaterialKind;\n");
    assert!(layer_violations(&c)
        .iter()
        .any(|v| v.contains("integrator (layer 5) reads the description (scene::desc)")));
    assert!(sibling_cycles(&c).is_empty(), "not a cycle: the checks are apart");
    // A cycle between two of scene's submodules.
    let c = plant("scene/geometry.rs", "\nuse super::build::build_geometry;\n");
    let cycles = sibling_cycles(&c);
    assert!(cycles.iter().any(|m| m.contains("scene::geometry uses scene::build")), "{cycles:?}");
    assert!(layer_violations(&c).iter().any(|v| v.contains("scene::geometry (layer 3) uses scene::build (layer 4)")));
}
