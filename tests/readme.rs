//! README.md's library snippet is the body of `examples/readme.rs`'s `main`,
//! so that the snippet compiles and runs as pasted into a `main` (the example
//! is built and checked by `cargo test` and `cargo clippy --all-targets`).
//! Change both together.

use std::path::Path;

fn read(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The lines of every fenced block that opens with ```` ```rust ````.
fn rust_blocks(markdown: &str) -> Vec<Vec<String>> {
    let (mut blocks, mut current): (Vec<Vec<String>>, Option<Vec<String>>) = (Vec::new(), None);
    for line in markdown.lines() {
        match current.as_mut() {
            None if line.trim_end() == "```rust" => current = Some(Vec::new()),
            None => {}
            Some(_) if line.trim_end() == "```" => blocks.extend(current.take()),
            Some(block) => block.push(line.to_string()),
        }
    }
    assert!(
        current.is_none(),
        "README.md: a ```rust block is never closed"
    );
    blocks
}

/// The body of the file's `fn main() {`, one indentation level removed.
fn main_body(source: &str) -> Vec<String> {
    let lines: Vec<&str> = source.lines().collect();
    let open = lines
        .iter()
        .position(|l| l.trim_end() == "fn main() {")
        .expect("examples/readme.rs has a `fn main() {` line");
    let close = lines
        .iter()
        .rposition(|l| l.trim_end() == "}")
        .expect("examples/readme.rs ends its main with `}`");
    assert!(
        open < close,
        "examples/readme.rs: main's braces out of order"
    );
    lines[open + 1..close]
        .iter()
        .map(|l| l.strip_prefix("    ").unwrap_or(l).trim_end().to_string())
        .collect()
}

#[test]
fn readme_snippet_is_the_example() {
    let blocks = rust_blocks(&read("README.md"));
    assert_eq!(
        blocks.len(),
        1,
        "README.md should hold exactly one ```rust block"
    );
    let snippet: Vec<String> = blocks[0].iter().map(|l| l.trim_end().to_string()).collect();
    let example = main_body(&read("examples/readme.rs"));
    for (i, (a, b)) in snippet.iter().zip(&example).enumerate() {
        assert_eq!(
            a,
            b,
            "README.md's snippet and examples/readme.rs differ at line {}",
            i + 1
        );
    }
    assert_eq!(
        snippet.len(),
        example.len(),
        "README.md's snippet and examples/readme.rs's main differ in length"
    );
}

#[test]
fn the_snippet_needs_no_hidden_lines_or_question_marks() {
    let snippet = rust_blocks(&read("README.md")).concat();
    for line in &snippet {
        assert!(
            !line.trim_start().starts_with("# "),
            "rustdoc hidden line: {line}"
        );
        assert!(
            !line.contains('?'),
            "`?` (the snippet runs in a plain main): {line}"
        );
    }
}
