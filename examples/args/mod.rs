//! What the examples that write documents share: the command line that
//! reproduces them.

/// The arguments after the program name, and the `cargo run` command
/// that passes them to `example` (the line a generated document names).
pub fn command_line(example: &str) -> (String, Vec<String>) {
    let list: Vec<String> = std::env::args().skip(1).collect();
    let command = match list.is_empty() {
        true => format!("cargo run --release --example {example}"),
        false => format!(
            "cargo run --release --example {example} -- {}",
            list.join(" ")
        ),
    };
    (command, list)
}
