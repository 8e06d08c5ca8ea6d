//! Generates the list of bundled scenarios and studies (`scenarios/*.toml`, `studies/*.toml`),
//! embedded in the library with `include_str!` (see `src/study/bundled.rs`). They live at the
//! workspace's top (`../../scenarios`, `../../studies`), where the project's paths name them.

use std::path::Path;

fn main() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR");
    let root = Path::new(&manifest).join("../..");
    let mut entries = Vec::new();
    for dir in ["scenarios", "studies"] {
        println!("cargo:rerun-if-changed=../../{dir}");
        let mut names: Vec<String> = std::fs::read_dir(root.join(dir))
            .map(|rd| {
                rd.filter_map(|e| e.ok())
                    .filter(|e| e.path().is_file())
                    .filter_map(|e| e.file_name().to_str().map(str::to_string))
                    .filter(|n| n.ends_with(".toml"))
                    .collect()
            })
            .unwrap_or_default();
        names.sort();
        for n in names {
            let rel = format!("{dir}/{n}");
            println!("cargo:rerun-if-changed=../../{rel}");
            entries.push(format!(
                "    ({rel:?}, include_str!(concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/../../{rel}\"))),\n"
            ));
        }
    }
    let out = Path::new(&std::env::var("OUT_DIR").expect("OUT_DIR")).join("bundled_files.rs");
    let text = format!(
        "/// Every bundled file: (path relative to the project root, contents).\npub const FILES: &[(&str, &str)] = &[\n{}];\n",
        entries.concat()
    );
    std::fs::write(out, text).expect("write bundled_files.rs");
}
