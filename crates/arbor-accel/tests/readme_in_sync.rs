//! The repository README's "Using the structures as a library" example is the crate README's first
//! example, which runs as a doc test (`lib.rs` includes the crate README): this test fails when the
//! two drift apart, so the example on the repository's front page always compiles and runs.
//!
//! It reads the repository's README, which a published crate does not ship: `Cargo.toml` leaves this
//! file out of the package.

use std::path::Path;

/// The first ```rust block of the Markdown text `md`.
fn first_rust_block(md: &str) -> Option<String> {
    let mut lines = md.lines().skip_while(|l| l.trim() != "```rust");
    lines.next()?;
    let block: Vec<&str> = lines.take_while(|l| l.trim() != "```").collect();
    Some(block.join("\n"))
}

/// `s` without any whitespace: line wrapping and indentation do not count as drift.
fn squeezed(s: &str) -> String {
    s.chars().filter(|c| !c.is_whitespace()).collect()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn readme_library_example_is_the_crate_doc_test() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let top = read(&crate_dir.join("../../README.md"));
    let section = top
        .split("\n## ")
        .find(|s| s.starts_with("Using the structures as a library"))
        .expect("README.md has a section \"Using the structures as a library\"");
    let shown = first_rust_block(section).expect("the section has a ```rust block");
    assert!(shown.contains("fn main"), "the section's first example is a whole program:\n{shown}");
    assert_eq!(first_rust_block(&top).as_deref(), Some(shown.as_str()), "no ```rust block comes before it");
    let tested = first_rust_block(&read(&crate_dir.join("README.md"))).expect("the crate README has an example");
    assert_eq!(squeezed(&shown), squeezed(&tested), "README.md's library example differs from crates/arbor-accel/README.md's first example (a doc test):\n{shown}\n---\n{tested}");
    let order: Vec<&str> = top.lines().filter(|l| l.starts_with("## ")).collect();
    let at = |h: &str| order.iter().position(|l| *l == h).unwrap_or_else(|| panic!("no heading {h}"));
    assert_eq!(at("## Using the structures as a library"), at("## Acceleration structures") + 1);
}

#[test]
fn readme_first_rust_block_skips_other_languages() {
    let md = "intro\n```sh\nls\n```\n```rust\nfn main() {}\n  let x = 1;\n```\n```rust\nother\n```\n";
    assert_eq!(first_rust_block(md).unwrap(), "fn main() {}\n  let x = 1;");
    assert_eq!(first_rust_block("no code"), None);
    assert_eq!(squeezed(" a\n\tb c "), "abc");
}
