//! The library's layering, read from its source: which top-level module of the library
//! (crates/pinfeed/src) names which (`crate::X` outside test modules and comments; `pinfeed::X` in
//! the command line, src/cli/, its own crate `pinfeed_cli`). The command line is not part of the
//! library and is named by no library module, the modules below the studies import nothing from
//! `study`, and the modules form no import circle.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The source files below `dir`.
fn files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The top-level modules each top-level module names (`crate::X`), without test modules and
/// comments.
fn graph() -> BTreeMap<String, BTreeSet<String>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let src = root.join("crates/pinfeed/src");
    let mut modules = BTreeMap::new();
    let mut cli = Vec::new();
    files(&root.join("src/cli"), &mut cli);
    modules.insert("cli".to_string(), cli);
    for e in std::fs::read_dir(&src).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_stem().unwrap().to_string_lossy().to_string();
        if name != "lib" {
            let mut fs = Vec::new();
            if p.is_dir() {
                files(&p, &mut fs);
            } else {
                fs.push(p);
            }
            modules.insert(name, fs);
        }
    }
    let names: BTreeSet<String> = modules.keys().cloned().collect();
    let mut g = BTreeMap::new();
    for (m, fs) in &modules {
        let mut uses = BTreeSet::new();
        for f in fs {
            let text = std::fs::read_to_string(f).unwrap();
            let code = text.split("#[cfg(test)]").next().unwrap();
            for line in code.lines() {
                let line = line.split("//").next().unwrap();
                let prefix = if m == "cli" { "pinfeed::" } else { "crate::" };
                for (i, _) in line.match_indices(prefix) {
                    let rest = &line[i + prefix.len()..];
                    let word: String = rest
                        .chars()
                        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                        .collect();
                    if names.contains(&word) && &word != m {
                        uses.insert(word);
                    }
                }
            }
        }
        g.insert(m.clone(), uses);
    }
    g
}

/// The modules reachable from `from`.
fn reach(g: &BTreeMap<String, BTreeSet<String>>, from: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut todo = vec![from.to_string()];
    while let Some(m) = todo.pop() {
        for n in &g[&m] {
            if seen.insert(n.clone()) {
                todo.push(n.clone());
            }
        }
    }
    seen
}

#[test]
fn the_library_never_names_the_command_line() {
    // The command line is its own crate, above the library: the library's manifest does not
    // depend on it, no library file names it, and the binary's main is the command line's.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest = std::fs::read_to_string(root.join("crates/pinfeed/Cargo.toml")).unwrap();
    assert!(manifest.contains("[dependencies]") && !manifest.contains("pinfeed-cli"));
    let mut lib_files = Vec::new();
    files(&root.join("crates/pinfeed/src"), &mut lib_files);
    assert!(lib_files.len() > 100, "{} library files", lib_files.len());
    for f in &lib_files {
        let text = std::fs::read_to_string(f).unwrap();
        assert!(
            !text.contains("pinfeed_cli") && !text.contains("crate::cli"),
            "{} names the command line",
            f.display()
        );
        if f.ends_with("lib.rs") {
            assert!(!text.lines().any(|l| {
                l.trim_start().starts_with("pub mod cli") || l.trim_start().starts_with("mod cli")
            }));
        }
    }
    let main = std::fs::read_to_string(root.join("src/main.rs")).unwrap();
    assert!(main.lines().any(|l| l == "use pinfeed_cli as cli;"));
    let g = graph();
    assert!(
        g["cli"].contains("plan"),
        "the scan sees cli's imports: {:?}",
        g["cli"]
    );
    for (m, uses) in &g {
        assert!(m == "cli" || !uses.contains("cli"), "{m} imports cli");
    }
}

#[test]
fn the_modules_below_the_studies_import_nothing_from_study() {
    let g = graph();
    for m in [
        "maps",
        "validate",
        "mechanics",
        "geometry",
        "scenario",
        "engine",
    ] {
        assert!(!g[m].contains("study"), "{m} imports study: {:?}", g[m]);
    }
}

#[test]
fn no_import_circle() {
    let g = graph();
    let circles: BTreeSet<&String> = g.keys().filter(|m| reach(&g, m).contains(*m)).collect();
    assert!(
        circles.is_empty(),
        "modules on an import circle: {circles:?}"
    );
    // The circle that was longest to go: parsing a scenario built the online controller's
    // model, which runs the engine. The engine builds it now (`engine::prepare`).
    assert!(!g["scenario"].contains("engine"), "{:?}", g["scenario"]);
}
