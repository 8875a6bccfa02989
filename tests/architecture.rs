//! The layering rules of docs/architecture.md, checked on the source: no library file outside
//! `src/cli/` (and the binary's `src/main.rs`) mentions a command-line flag, and no two top-level
//! modules of `src/` depend on each other through any chain of `crate::` paths (comments and doc
//! links do not count). `scripts/module_deps.py` prints the same graph.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

fn library_files() -> Vec<PathBuf> {
    let mut all = Vec::new();
    rust_files(&src(), &mut all);
    all.retain(|p| {
        let rel = p.strip_prefix(src()).unwrap();
        !rel.starts_with("cli") && rel != Path::new("main.rs")
    });
    all.sort();
    all
}

#[test]
fn no_library_file_names_a_flag() {
    let mut found = Vec::new();
    for f in library_files() {
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in text.lines().enumerate() {
            let b = line.as_bytes();
            for i in 0..b.len().saturating_sub(3) {
                // `--word`, not `---`, not `x--y` (a decrement or a table rule).
                let flag = b[i] == b'-'
                    && b[i + 1] == b'-'
                    && b[i + 2].is_ascii_lowercase()
                    && b[i + 3].is_ascii_lowercase()
                    && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'-'));
                if flag {
                    found.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
                    break;
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "name option paths (`steady.fps`) instead; the CLI maps them (src/cli/flags.rs):\n{}",
        found.join("\n")
    );
}

#[test]
fn no_import_cycles_between_top_level_modules() {
    let top = |p: &Path| -> String {
        let rel = p.strip_prefix(src()).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        first.trim_end_matches(".rs").to_string()
    };
    let files = library_files();
    let modules: BTreeSet<String> = files
        .iter()
        .map(|p| top(p))
        .filter(|m| m != "lib")
        .collect();
    let mut deps: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in &files {
        let m = top(f);
        if m == "lib" {
            continue;
        }
        for line in std::fs::read_to_string(f).unwrap().lines() {
            let code = line.split("//").next().unwrap();
            for (i, _) in code.match_indices("crate::") {
                let name: String = code[i + 7..]
                    .chars()
                    .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                    .collect();
                if name != m && modules.contains(&name) {
                    deps.entry(m.clone()).or_default().insert(name);
                }
            }
        }
    }
    let reaches = |from: &str, to: &str| {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.to_string()];
        while let Some(x) = stack.pop() {
            for d in deps.get(&x).into_iter().flatten() {
                if d == to {
                    return true;
                }
                if seen.insert(d.clone()) {
                    stack.push(d.clone());
                }
            }
        }
        false
    };
    let mut cycles = BTreeSet::new();
    for (m, ds) in &deps {
        for d in ds {
            if reaches(d, m) {
                let (a, b) = if m < d { (m, d) } else { (d, m) };
                cycles.insert(format!("{a} <-> {b}"));
            }
        }
    }
    assert!(
        cycles.is_empty(),
        "import cycles: {cycles:?} (graph: {deps:?})"
    );
    // The data types stay below the stages.
    for data in ["animation", "annotations", "shape", "sniff"] {
        for stage in [
            "extract", "keyshape", "initiate", "wingbeat", "export", "plot", "pipeline",
        ] {
            assert!(!reaches(data, stage), "{data} depends on the stage {stage}");
        }
    }
}

#[test]
fn no_import_cycles_between_the_files_of_a_module() {
    // Inside each directory module (src/aero/, src/extract/, ...), the sibling files import one
    // another in one direction only (the parent mod.rs is left out: it gathers its children).
    let mut cycles = Vec::new();
    for entry in std::fs::read_dir(src()).unwrap() {
        let dir = entry.unwrap().path();
        if !dir.is_dir() {
            continue;
        }
        let module = dir.file_name().unwrap().to_string_lossy().into_owned();
        let mut files: BTreeMap<String, String> = BTreeMap::new();
        for f in std::fs::read_dir(&dir).unwrap() {
            let p = f.unwrap().path();
            let name = p.file_stem().unwrap().to_string_lossy().into_owned();
            if p.extension().is_some_and(|e| e == "rs") && name != "mod" {
                // Code outside the file's unit tests.
                let text = std::fs::read_to_string(&p).unwrap();
                let code = text.split("#[cfg(test)]").next().unwrap_or("").to_string();
                files.insert(name, code);
            }
        }
        let mut deps: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
        for (name, code) in &files {
            for line in code.lines() {
                let line = line.split("//").next().unwrap();
                for prefix in ["super::".to_string(), format!("crate::{module}::")] {
                    for (i, _) in line.match_indices(prefix.as_str()) {
                        let rest = &line[i + prefix.len()..];
                        let mut names: Vec<&str> = Vec::new();
                        if let Some(group) = rest.strip_prefix('{') {
                            names.extend(
                                group
                                    .split('}')
                                    .next()
                                    .unwrap()
                                    .split(',')
                                    .map(|s| s.trim().split("::").next().unwrap().trim()),
                            );
                        } else {
                            names.push(
                                rest.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                                    .next()
                                    .unwrap(),
                            );
                        }
                        for n in names {
                            if let Some((k, _)) = files.get_key_value(n) {
                                if k != name {
                                    deps.entry(name.as_str()).or_default().insert(k.as_str());
                                }
                            }
                        }
                    }
                }
            }
        }
        let reaches = |from: &str, to: &str| {
            let mut seen = BTreeSet::new();
            let mut stack = vec![from];
            while let Some(x) = stack.pop() {
                for d in deps.get(x).into_iter().flatten() {
                    if *d == to {
                        return true;
                    }
                    if seen.insert(*d) {
                        stack.push(d);
                    }
                }
            }
            false
        };
        for (m, ds) in &deps {
            for d in ds {
                if m < d && reaches(d, m) {
                    cycles.push(format!("{module}: {m} <-> {d}"));
                }
            }
        }
    }
    assert!(
        cycles.is_empty(),
        "import cycles inside modules: {cycles:?}"
    );
}
