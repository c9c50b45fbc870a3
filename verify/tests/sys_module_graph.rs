//! No cycle between the modules of a crate.
//!
//! For every workspace crate (`data`, `fem`, `fdm`, `modal`, `verify`) the test reads
//! `src/**/*.rs`, collects the intra-crate module dependencies and checks two graphs for cycles:
//!
//! * the **top-level graph**: nodes are the crate root (`lib.rs`) and its top-level modules
//!   (`src/a.rs` or `src/a/mod.rs`, everything below `a` folded into `a`);
//! * one **submodule graph per top-level module**: nodes are the parent's own file (`a.rs` or
//!   `a/mod.rs`) and its direct submodules (`a/b.rs` or `a/b/mod.rs`, deeper files folded into `b`).
//!
//! A dependency of module S on module T is any of
//! * a `use` tree naming `crate::…`, `super::…`, `self::…` or a child module of S;
//! * a path expression `crate::…`, `super::…` (resolved to the parent module), `self::…`, or
//!   `child::…` (a declared child module of S) in code.
//!
//! A path is resolved to the deepest declared module it names; if the next segment is an item the
//! module re-exports (`pub use b::Item`), it is followed to the module that defines it, so a
//! dependency through a facade counts against the module behind it. A parent's `pub use` of its
//! own descendants is the facade itself and not an edge (otherwise every parent whose submodules
//! use one of its items would be a cycle by construction); a `pub use` of any other module is.
//!
//! Ignored, with the reason:
//! * comments and string/char literals (intra-doc links like ``[`crate::chain`]`` are not code);
//! * items under `#[cfg(test)]` (inline `mod tests`, test-only `mod x;` files): test code may
//!   reach across layers to build fixtures, it is not part of the library's structure;
//! * `tests/`, `benches/` and `src/main.rs` (separate crates that see the library from outside);
//! * `$crate::` in macros (a path into the crate root from the expansion site, not an edge of the
//!   defining module) and inline `mod x { … }` blocks, which are folded into their file's module.
//!
//! Std only: a character-level cleaner and a small `use`-tree parser, no syntax crate.

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::{Path, PathBuf};

/// One source file: path relative to `src/` with `/` separators, and its text.
struct Source {
    rel: String,
    text: String,
}

/// Where an edge was seen: the file, the line, and that line's text.
#[derive(Clone, Debug)]
struct Evidence {
    rel: String,
    line: usize,
    text: String,
}

/// A dependency cycle in one graph: the chain of nodes (first repeated at the end) and, for each
/// edge, one line that creates it.
#[derive(Debug)]
struct Cycle {
    graph: String,
    nodes: Vec<String>,
    evidence: Vec<Evidence>,
}

impl std::fmt::Display for Cycle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "cycle in {}: {}", self.graph, self.nodes.join(" → "))?;
        for (pair, ev) in self.nodes.windows(2).zip(&self.evidence) {
            writeln!(
                f,
                "    {} → {}: src/{}:{}: {}",
                pair[0], pair[1], ev.rel, ev.line, ev.text
            )?;
        }
        Ok(())
    }
}

type ModPath = Vec<String>;

fn is_ident_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Replaces comments and string/char literals by spaces, keeping newlines (so byte offsets keep
/// their line numbers).
fn strip_comments_and_literals(src: &str) -> String {
    let c: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(src.len());
    let blank = |out: &mut String, ch: char| out.push(if ch == '\n' { '\n' } else { ' ' });
    let mut i = 0;
    while i < c.len() {
        let prev_ident = i > 0 && is_ident_char(c[i - 1]);
        if c[i] == '/' && c.get(i + 1) == Some(&'/') {
            while i < c.len() && c[i] != '\n' {
                out.push(' ');
                i += 1;
            }
        } else if c[i] == '/' && c.get(i + 1) == Some(&'*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    blank(&mut out, c[i]);
                    i += 1;
                }
            }
        } else if (c[i] == 'r' || (c[i] == 'b' && c.get(i + 1) == Some(&'r'))) && !prev_ident && {
            let mut j = i + if c[i] == 'b' { 2 } else { 1 };
            while c.get(j) == Some(&'#') {
                j += 1;
            }
            c.get(j) == Some(&'"')
        } {
            let start = i + if c[i] == 'b' { 2 } else { 1 };
            let mut j = start;
            while c[j] == '#' {
                j += 1;
            }
            let hashes = j - start;
            for &ch in &c[i..=j] {
                blank(&mut out, ch);
            }
            i = j + 1;
            while i < c.len() {
                if c[i] == '"' && (1..=hashes).all(|k| c.get(i + k) == Some(&'#')) {
                    for _ in 0..=hashes {
                        out.push(' ');
                    }
                    i += hashes + 1;
                    break;
                }
                blank(&mut out, c[i]);
                i += 1;
            }
        } else if c[i] == '"' {
            out.push(' ');
            i += 1;
            while i < c.len() {
                if c[i] == '\\' {
                    blank(&mut out, c[i]);
                    if let Some(&n) = c.get(i + 1) {
                        blank(&mut out, n);
                    }
                    i += 2;
                } else if c[i] == '"' {
                    out.push(' ');
                    i += 1;
                    break;
                } else {
                    blank(&mut out, c[i]);
                    i += 1;
                }
            }
        } else if c[i] == '\'' && !prev_ident {
            // A char literal ('x', '\n', '\u{..}') or a lifetime/label ('a): only the former is
            // closed by a quote right after its one character or escape.
            if c.get(i + 1) == Some(&'\\') {
                let mut j = i + 2;
                while j < c.len() && c[j] != '\'' {
                    j += 1;
                }
                for _ in i..=j.min(c.len() - 1) {
                    out.push(' ');
                }
                i = j + 1;
            } else if c.get(i + 2) == Some(&'\'') {
                out.push_str("   ");
                i += 3;
            } else {
                out.push('\'');
                i += 1;
            }
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// Blanks every item carrying `#[cfg(test)]` (the attribute, further attributes, and the item up
/// to its `;` or its matching `}`).
fn strip_cfg_test(code: &str) -> String {
    let mut c: Vec<char> = code.chars().collect();
    let pat: Vec<char> = "#[cfg(test)]".chars().collect();
    let mut i = 0;
    while i + pat.len() <= c.len() {
        if c[i..i + pat.len()] != pat[..] {
            i += 1;
            continue;
        }
        let start = i;
        let mut j = i + pat.len();
        let mut depth = 0i32;
        let mut end = c.len();
        while j < c.len() {
            match c[j] {
                '(' | '[' => depth += 1,
                ')' | ']' => depth -= 1,
                ';' if depth == 0 => {
                    end = j + 1;
                    break;
                }
                '{' if depth == 0 => {
                    let mut braces = 0;
                    while j < c.len() {
                        if c[j] == '{' {
                            braces += 1;
                        } else if c[j] == '}' {
                            braces -= 1;
                            if braces == 0 {
                                break;
                            }
                        }
                        j += 1;
                    }
                    end = (j + 1).min(c.len());
                    break;
                }
                _ => {}
            }
            j += 1;
        }
        for ch in &mut c[start..end] {
            if *ch != '\n' {
                *ch = ' ';
            }
        }
        i = end;
    }
    c.into_iter().collect()
}

/// Module path of a file under `src/`: `lib.rs` → [], `a.rs`/`a/mod.rs` → [a], `a/b.rs` → [a, b].
fn module_path(rel: &str) -> ModPath {
    let mut parts: Vec<String> = rel.split('/').map(str::to_string).collect();
    let file = parts.pop().unwrap_or_default();
    let stem = file.trim_end_matches(".rs");
    if stem != "mod" && !(parts.is_empty() && (stem == "lib" || stem == "main")) {
        parts.push(stem.to_string());
    }
    parts
}

/// Identifiers `x` of `mod x;` declarations (file modules) in cleaned code.
fn declared_file_modules(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (pos, _) in code.match_indices("mod") {
        if pos > 0 && is_ident_char(code[..pos].chars().next_back().unwrap_or(' ')) {
            continue;
        }
        let rest = &code[pos + 3..];
        if !rest.starts_with(char::is_whitespace) {
            continue;
        }
        let rest = rest.trim_start();
        let name: String = rest.chars().take_while(|&ch| is_ident_char(ch)).collect();
        if !name.is_empty() && rest[name.len()..].trim_start().starts_with(';') {
            out.insert(name);
        }
    }
    out
}

/// A `use` statement (or a path in code), expanded: the path segments, the name it binds (alias
/// or last segment), and where it starts.
struct UsePath {
    segs: Vec<String>,
    bound: String,
}

/// Expands a `use` tree (`a::{b, c::d as e, self}`) into its leaf paths.
fn expand_use_tree(tree: &str, prefix: &[String], out: &mut Vec<UsePath>) {
    let tree = tree.trim();
    if let Some(open) = tree.find('{') {
        let head = tree[..open].trim().trim_end_matches("::");
        let mut base = prefix.to_vec();
        base.extend(
            head.split("::")
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .map(str::to_string),
        );
        let close = tree.rfind('}').unwrap_or(tree.len());
        let inner = &tree[open + 1..close];
        let mut depth = 0;
        let mut last = 0;
        for (k, ch) in inner.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand_use_tree(&inner[last..k], &base, out);
                    last = k + 1;
                }
                _ => {}
            }
        }
        expand_use_tree(&inner[last..], &base, out);
        return;
    }
    if tree.is_empty() {
        return;
    }
    let (path, alias) = match tree.split_once(" as ") {
        Some((p, a)) => (p.trim(), Some(a.trim().to_string())),
        None => (tree, None),
    };
    let mut segs = prefix.to_vec();
    segs.extend(
        path.split("::")
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(str::to_string),
    );
    if segs.last().map(String::as_str) == Some("self") {
        segs.pop();
    }
    let bound = alias.unwrap_or_else(|| segs.last().cloned().unwrap_or_default());
    out.push(UsePath { segs, bound });
}

/// Turns a path as written in module `m` into an absolute module-relative path (segments after
/// `crate`), or `None` for a path outside the crate.
fn absolutize(segs: &[String], m: &ModPath, children: &BTreeSet<String>) -> Option<ModPath> {
    let first = segs.first()?;
    let mut base: ModPath;
    let mut rest = segs;
    match first.as_str() {
        "crate" => {
            base = Vec::new();
            rest = &segs[1..];
        }
        "self" => {
            base = m.clone();
            rest = &segs[1..];
        }
        "super" => {
            base = m.clone();
            while rest.first().map(String::as_str) == Some("super") {
                base.pop()?;
                rest = &rest[1..];
            }
        }
        name if children.contains(name) => base = m.clone(),
        _ => return None,
    }
    base.extend(rest.iter().cloned());
    Some(base)
}

/// One crate's module tree, re-exports and dependency edges.
struct CrateGraph {
    name: String,
    /// (source module, target module) → first evidence.
    edges: BTreeMap<(ModPath, ModPath), Evidence>,
}

struct Parsed {
    rel: String,
    module: ModPath,
    code: String,
    lines: Vec<String>,
}

fn line_of(code: &str, pos: usize) -> usize {
    code[..pos].matches('\n').count() + 1
}

/// Positions and texts of the `use …;` statements of cleaned code, and whether each is `pub`.
fn use_statements(code: &str) -> Vec<(usize, usize, String, bool)> {
    let mut out = Vec::new();
    for (pos, _) in code.match_indices("use") {
        let before = code[..pos].chars().next_back().unwrap_or(' ');
        let after = code[pos + 3..].chars().next().unwrap_or(' ');
        if is_ident_char(before) || !after.is_whitespace() {
            continue;
        }
        let Some(semi) = code[pos..].find(';') else {
            continue;
        };
        let tree = code[pos + 3..pos + semi].to_string();
        let head = code[..pos].trim_end();
        let public = head.ends_with("pub")
            || (head.ends_with(')') && {
                let open = head.rfind('(').unwrap_or(0);
                head[..open].trim_end().ends_with("pub")
            });
        out.push((pos, pos + semi + 1, tree, public));
    }
    out
}

/// Resolves an absolute path to the deepest declared module, following re-exports of the item
/// named next.
fn resolve(
    abs: &ModPath,
    modules: &BTreeSet<ModPath>,
    reexports: &BTreeMap<ModPath, BTreeMap<String, ModPath>>,
) -> ModPath {
    let mut k = abs.len();
    while k > 0 && !modules.contains(&abs[..k].to_vec()) {
        k -= 1;
    }
    let mut target = abs[..k].to_vec();
    let mut item = abs.get(k).cloned();
    // Follow re-export chains (bounded: a re-export loop would not compile).
    for _ in 0..8 {
        let Some(name) = item.as_ref() else { break };
        let Some(next) = reexports.get(&target).and_then(|r| r.get(name)) else {
            break;
        };
        let mut kk = next.len();
        while kk > 0 && !modules.contains(&next[..kk].to_vec()) {
            kk -= 1;
        }
        if next[..kk] == target[..] {
            break;
        }
        item = next.get(kk).cloned();
        target = next[..kk].to_vec();
    }
    target
}

fn build_graph(name: &str, sources: &[Source]) -> CrateGraph {
    let mut parsed: Vec<Parsed> = sources
        .iter()
        .filter(|s| s.rel != "main.rs")
        .map(|s| Parsed {
            rel: s.rel.clone(),
            module: module_path(&s.rel),
            code: strip_cfg_test(&strip_comments_and_literals(&s.text)),
            lines: s.text.lines().map(|l| l.trim().to_string()).collect(),
        })
        .collect();
    // Keep the files reachable through `mod x;` declarations (this drops test-only modules).
    let declared: BTreeMap<ModPath, BTreeSet<String>> = parsed
        .iter()
        .map(|p| (p.module.clone(), declared_file_modules(&p.code)))
        .collect();
    let reachable = |m: &ModPath| -> bool {
        (1..=m.len()).all(|k| {
            declared
                .get(&m[..k - 1])
                .is_some_and(|d| d.contains(&m[k - 1]))
        })
    };
    parsed.retain(|p| reachable(&p.module));
    let modules: BTreeSet<ModPath> = parsed.iter().map(|p| p.module.clone()).collect();
    let children_of = |m: &ModPath| -> BTreeSet<String> {
        modules
            .iter()
            .filter(|c| c.len() == m.len() + 1 && c[..m.len()] == m[..])
            .map(|c| c[m.len()].clone())
            .collect()
    };

    // Re-exports: module → (bound name → absolute path of the re-exported item).
    let mut reexports: BTreeMap<ModPath, BTreeMap<String, ModPath>> = BTreeMap::new();
    for p in &parsed {
        let children = children_of(&p.module);
        for (_, _, tree, public) in use_statements(&p.code) {
            if !public {
                continue;
            }
            let mut leaves = Vec::new();
            expand_use_tree(&tree, &[], &mut leaves);
            for leaf in leaves {
                if let Some(abs) = absolutize(&leaf.segs, &p.module, &children) {
                    reexports
                        .entry(p.module.clone())
                        .or_default()
                        .insert(leaf.bound, abs);
                }
            }
        }
    }

    let mut edges: BTreeMap<(ModPath, ModPath), Evidence> = BTreeMap::new();
    for p in &parsed {
        let children = children_of(&p.module);
        let add = |abs: &ModPath, pos: usize, edges: &mut BTreeMap<_, _>| {
            let target = resolve(abs, &modules, &reexports);
            if target == p.module {
                return;
            }
            let line = line_of(&p.code, pos);
            edges
                .entry((p.module.clone(), target))
                .or_insert_with(|| Evidence {
                    rel: p.rel.clone(),
                    line,
                    text: p.lines.get(line - 1).cloned().unwrap_or_default(),
                });
        };
        let mut code = p.code.clone();
        for (start, end, tree, public) in use_statements(&p.code) {
            let mut leaves = Vec::new();
            expand_use_tree(&tree, &[], &mut leaves);
            for leaf in leaves {
                let Some(abs) = absolutize(&leaf.segs, &p.module, &children) else {
                    continue;
                };
                // The facade re-exporting its own descendants is not a dependency.
                if public && abs.len() > p.module.len() && abs[..p.module.len()] == p.module[..] {
                    continue;
                }
                add(&abs, start, &mut edges);
            }
            code.replace_range(start..end, &" ".repeat(end - start));
        }
        // Path expressions in code.
        let chars: Vec<(usize, char)> = code.char_indices().collect();
        let mut k = 0;
        while k < chars.len() {
            let (pos, ch) = chars[k];
            let at_start = k == 0 || {
                let prev = chars[k - 1].1;
                !is_ident_char(prev) && prev != '$' && prev != ':'
            };
            if !(at_start && (ch.is_alphabetic() || ch == '_')) {
                k += 1;
                continue;
            }
            // Read `ident(::ident)*`.
            let mut segs = Vec::new();
            let mut j = k;
            loop {
                let s = j;
                while j < chars.len() && is_ident_char(chars[j].1) {
                    j += 1;
                }
                let seg: String = chars[s..j].iter().map(|&(_, c)| c).collect();
                segs.push(seg);
                let mut t = j;
                while t < chars.len() && chars[t].1.is_whitespace() {
                    t += 1;
                }
                if t + 2 < chars.len()
                    && chars[t].1 == ':'
                    && chars[t + 1].1 == ':'
                    && (is_ident_char(chars[t + 2].1) || chars[t + 2].1.is_whitespace())
                {
                    let mut u = t + 2;
                    while u < chars.len() && chars[u].1.is_whitespace() {
                        u += 1;
                    }
                    if u < chars.len() && is_ident_char(chars[u].1) {
                        j = u;
                        continue;
                    }
                }
                break;
            }
            if segs.len() >= 2 {
                let first = segs[0].as_str();
                if (matches!(first, "crate" | "super" | "self") || children.contains(first))
                    && let Some(abs) = absolutize(&segs, &p.module, &children)
                {
                    add(&abs, pos, &mut edges);
                }
            }
            k = j.max(k + 1);
        }
    }
    CrateGraph {
        name: name.to_string(),
        edges,
    }
}

fn node_name(crate_name: &str, m: &[String]) -> String {
    if m.is_empty() {
        format!("{crate_name} (lib.rs)")
    } else {
        format!("{crate_name}::{}", m.join("::"))
    }
}

/// The graphs to check: the top-level one and one per top-level module, each as node → (node →
/// evidence).
fn graphs(g: &CrateGraph) -> BTreeMap<String, BTreeMap<String, BTreeMap<String, Evidence>>> {
    let mut out: BTreeMap<String, BTreeMap<String, BTreeMap<String, Evidence>>> = BTreeMap::new();
    for ((s, t), ev) in &g.edges {
        let top = |m: &ModPath| node_name(&g.name, &m[..m.len().min(1)]);
        let (ns, nt) = (top(s), top(t));
        if ns != nt {
            out.entry(format!("{} top-level modules", g.name))
                .or_default()
                .entry(ns)
                .or_default()
                .entry(nt)
                .or_insert_with(|| ev.clone());
        }
        if !s.is_empty() && !t.is_empty() && s[0] == t[0] {
            let sub = |m: &ModPath| {
                if m.len() == 1 {
                    format!("{} (own file)", node_name(&g.name, m))
                } else {
                    node_name(&g.name, &m[..2])
                }
            };
            let (ns, nt) = (sub(s), sub(t));
            if ns != nt {
                out.entry(format!("{}::{} submodules", g.name, s[0]))
                    .or_default()
                    .entry(ns)
                    .or_default()
                    .entry(nt)
                    .or_insert_with(|| ev.clone());
            }
        }
    }
    out
}

/// One cycle per strongly connected component with more than one node (the shortest cycle
/// through its smallest node), in a deterministic order.
fn find_cycles(g: &CrateGraph) -> Vec<Cycle> {
    let mut cycles = Vec::new();
    for (graph_name, adj) in graphs(g) {
        let nodes: BTreeSet<&String> = adj
            .iter()
            .flat_map(|(s, ts)| std::iter::once(s).chain(ts.keys()))
            .collect();
        let reach = |from: &String| -> BTreeSet<String> {
            let mut seen = BTreeSet::new();
            let mut queue = VecDeque::from([from.clone()]);
            while let Some(n) = queue.pop_front() {
                for t in adj.get(&n).into_iter().flat_map(|m| m.keys()) {
                    if seen.insert(t.clone()) {
                        queue.push_back(t.clone());
                    }
                }
            }
            seen
        };
        let mut done: BTreeSet<String> = BTreeSet::new();
        for &n in &nodes {
            if done.contains(n) {
                continue;
            }
            let fwd = reach(n);
            if !fwd.contains(n) {
                continue;
            }
            let scc: BTreeSet<String> = fwd
                .iter()
                .filter(|m| reach(m).contains(n))
                .cloned()
                .collect();
            done.extend(scc.iter().cloned());
            // Shortest cycle n → … → n inside the component (BFS with parents).
            let mut parent: BTreeMap<String, String> = BTreeMap::new();
            let mut queue = VecDeque::from([n.clone()]);
            let mut closing = None;
            'bfs: while let Some(u) = queue.pop_front() {
                for t in adj.get(&u).into_iter().flat_map(|m| m.keys()) {
                    if t == n {
                        closing = Some(u.clone());
                        break 'bfs;
                    }
                    if scc.contains(t) && !parent.contains_key(t) {
                        parent.insert(t.clone(), u.clone());
                        queue.push_back(t.clone());
                    }
                }
            }
            // Walk back from the node that closes the cycle: n → c₁ → … → u → n.
            let mut back = vec![closing.expect("a node of a cycle reaches itself")];
            while let Some(p) = parent.get(back.last().expect("non-empty")) {
                back.push(p.clone());
            }
            back.pop();
            let chain: Vec<String> = std::iter::once(n.clone())
                .chain(back.into_iter().rev())
                .chain(std::iter::once(n.clone()))
                .collect();
            let evidence = chain
                .windows(2)
                .map(|w| adj[&w[0]][&w[1]].clone())
                .collect();
            cycles.push(Cycle {
                graph: graph_name.clone(),
                nodes: chain,
                evidence,
            });
        }
    }
    cycles
}

fn read_crate(dir: &Path) -> Vec<Source> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<Source>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("read {}: {e}", dir.display()))
            .map(|e| e.expect("directory entry").path())
            .collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                walk(root, &path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path
                    .strip_prefix(root)
                    .expect("under src")
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect::<Vec<_>>()
                    .join("/");
                let text = std::fs::read_to_string(&path)
                    .unwrap_or_else(|e| panic!("read {}: {e}", path.display()));
                out.push(Source { rel, text });
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out
}

fn synthetic(files: &[(&str, &str)]) -> Vec<Cycle> {
    let sources: Vec<Source> = files
        .iter()
        .map(|&(rel, text)| Source {
            rel: rel.to_string(),
            text: text.to_string(),
        })
        .collect();
    find_cycles(&build_graph("demo", &sources))
}

#[test]
fn sys_module_graph_workspace_has_no_cycle() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut report = String::new();
    for name in ["data", "fem", "fdm", "modal", "verify"] {
        let g = build_graph(name, &read_crate(&root.join(name).join("src")));
        // The scanner must see the crate's structure, or "no cycle" would mean nothing.
        let top_edges = g
            .edges
            .keys()
            .filter(|(s, t)| s.first() != t.first())
            .count();
        assert!(
            top_edges > 0,
            "{name}: no dependency between top-level modules found"
        );
        for c in find_cycles(&g) {
            report.push_str(&c.to_string());
        }
    }
    // A cycle through a parent's own file ("(own file)") means that file both defines what its
    // submodules share and uses them: the shared items belong in a sibling leaf module that the
    // parent re-exports (as in `fem::driver::state`, `fem::element::contract`,
    // `fdm::chain::model`).
    assert!(report.is_empty(), "module cycles:\n{report}");
}

#[test]
fn sys_module_graph_reports_a_sibling_cycle_with_its_lines() {
    let cycles = synthetic(&[
        ("lib.rs", "mod a;\npub mod b;\n"),
        ("a/mod.rs", "mod x;\nmod y;\nmod z;\npub use x::run;\n"),
        ("a/x.rs", "use super::y::Y;\npub fn run() {}\n"),
        ("a/y.rs", "pub struct Y;\nfn f() { crate::a::z::g(); }\n"),
        ("a/z.rs", "pub fn g() {\n    super::x::run();\n}\n"),
        ("b.rs", "use crate::a::run;\n"),
    ]);
    assert_eq!(cycles.len(), 1, "{cycles:?}");
    let c = &cycles[0];
    assert_eq!(c.graph, "demo::a submodules");
    assert_eq!(
        c.nodes,
        ["demo::a::x", "demo::a::y", "demo::a::z", "demo::a::x"]
    );
    let lines: Vec<(&str, usize)> = c
        .evidence
        .iter()
        .map(|e| (e.rel.as_str(), e.line))
        .collect();
    assert_eq!(lines, [("a/x.rs", 1), ("a/y.rs", 2), ("a/z.rs", 2)]);
    assert_eq!(c.evidence[2].text, "super::x::run();");
    let shown = c.to_string();
    assert!(
        shown.contains("demo::a::y → demo::a::z: src/a/y.rs:2:"),
        "{shown}"
    );
}

#[test]
fn sys_module_graph_accepts_a_layered_crate() {
    let cycles = synthetic(&[
        (
            "lib.rs",
            "pub mod model;\npub mod method;\npub mod driver;\npub use driver::run;\n",
        ),
        ("model.rs", "pub struct Model;\n"),
        (
            "method/mod.rs",
            "mod a;\nmod b;\npub use a::A;\npub use b::B;\npub trait Stepper {}\n",
        ),
        (
            "method/a.rs",
            "use super::Stepper;\nuse crate::model::Model;\npub struct A;\n",
        ),
        (
            "method/b.rs",
            "use super::{Stepper, a::A};\npub struct B(A);\n",
        ),
        (
            "driver.rs",
            "use crate::method::{A, B};\npub fn run(_: &crate::model::Model) {}\n",
        ),
    ]);
    assert!(cycles.is_empty(), "{cycles:?}");
}

#[test]
fn sys_module_graph_reports_a_top_level_cycle_through_a_facade() {
    // `driver` uses `method::Stepper`, re-exported by `method/mod.rs` from `method::core`,
    // which calls back into `driver`: the edge counts against the module behind the facade.
    let cycles = synthetic(&[
        ("lib.rs", "mod method;\nmod driver;\n"),
        (
            "method/mod.rs",
            "mod core;\npub use self::core::Stepper as S;\n",
        ),
        (
            "method/core.rs",
            "pub trait Stepper {}\nfn f() -> usize { crate::driver::LIMIT }\n",
        ),
        (
            "driver.rs",
            "pub const LIMIT: usize = 3;\nuse crate::method::S;\n",
        ),
    ]);
    assert_eq!(cycles.len(), 1, "{cycles:?}");
    assert_eq!(cycles[0].graph, "demo top-level modules");
    assert_eq!(
        cycles[0].nodes,
        ["demo::driver", "demo::method", "demo::driver"]
    );
    assert_eq!(cycles[0].evidence[0].text, "use crate::method::S;");
    // Inside `method`, the facade's re-export is not an edge, so no submodule cycle either.
}

#[test]
fn sys_module_graph_ignores_tests_comments_and_literals() {
    let cycles = synthetic(&[
        ("lib.rs", "mod a;\nmod b;\n#[cfg(test)]\nmod fixtures;\n"),
        (
            "a.rs",
            "use crate::b::B;\n/// See [`crate::b`]; /* crate::b::x() */\npub struct A;\n",
        ),
        (
            "b.rs",
            concat!(
                "pub struct B;\n",
                "const S: &str = \"crate::a::A\";\n",
                "const R: &str = r#\"use crate::a::A;\"#;\n",
                "const Q: char = '\"';\n",
                "fn f<'a>(x: &'a str) -> &'a str { x }\n",
                "#[cfg(test)]\nuse crate::a::A;\n",
                "#[cfg(test)]\nmod tests {\n    use crate::a::A;\n    fn t() { let _ = crate::a::A; }\n}\n",
            ),
        ),
        ("fixtures.rs", "use crate::a::A;\nuse crate::b::B;\n"),
    ]);
    assert!(cycles.is_empty(), "{cycles:?}");
    // The same edge outside test code closes the cycle.
    let cycles = synthetic(&[
        ("lib.rs", "mod a;\nmod b;\n"),
        ("a.rs", "use crate::b::B;\npub struct A;\n"),
        (
            "b.rs",
            "pub struct B;\nconst Q: char = '\"';\nfn f() -> crate::a::A { crate::a::A }\n",
        ),
    ]);
    assert_eq!(cycles.len(), 1, "{cycles:?}");
    assert_eq!(cycles[0].nodes, ["demo::a", "demo::b", "demo::a"]);
}

#[test]
fn sys_module_graph_reports_a_parent_file_cycle_and_accepts_its_leaf_split() {
    // The parent's own file defines what its child extends and calls into the child.
    let cycles = synthetic(&[
        ("lib.rs", "pub mod a;\n"),
        (
            "a/mod.rs",
            "mod x;\npub struct S;\nfn f() -> usize { x::g() }\n",
        ),
        ("a/x.rs", "use super::S;\npub fn g() -> usize { 1 }\n"),
    ]);
    assert_eq!(cycles.len(), 1, "{cycles:?}");
    assert_eq!(cycles[0].graph, "demo::a submodules");
    assert_eq!(
        cycles[0].nodes,
        ["demo::a (own file)", "demo::a::x", "demo::a (own file)"]
    );
    // The shared type in a sibling leaf that the parent re-exports: no cycle.
    let cycles = synthetic(&[
        ("lib.rs", "pub mod a;\n"),
        (
            "a/mod.rs",
            "mod s;\nmod x;\npub use s::S;\nfn f() -> usize { x::g() }\n",
        ),
        ("a/s.rs", "pub struct S;\n"),
        ("a/x.rs", "use super::S;\npub fn g() -> usize { 1 }\n"),
    ]);
    assert!(cycles.is_empty(), "{cycles:?}");
}
