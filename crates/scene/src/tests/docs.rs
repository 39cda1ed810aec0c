//! README.md's copy of the MTL table held to the table's one statement, in `src/load/mtl.rs`.

// Read at compile time: cargo rebuilds the tests when either file changes.
const README: &str = include_str!("../../../../README.md");
const MTL_RS: &str = include_str!("../load/mtl.rs");

/// The module doc of a Rust file, without its `//!` markers.
fn module_doc(rs: &str) -> Vec<&str> {
    rs.lines()
        .map_while(|l| l.strip_prefix("//!"))
        .map(|l| l.strip_prefix(' ').unwrap_or(l))
        .collect()
}

/// The lines of README's section `heading`, up to the next heading.
fn readme_section<'a>(readme: &'a str, heading: &str) -> Vec<&'a str> {
    let mut lines = readme.lines();
    assert!(
        lines.any(|l| l.trim_end() == heading),
        "README.md has no `{heading}` section"
    );
    lines.take_while(|l| !l.starts_with('#')).collect()
}

/// The rows of the first Markdown table in `lines`, and the paragraph just before it (its
/// lines joined by single spaces, so a rewrap is no difference).
fn table_and_intro<'a>(lines: &[&'a str]) -> (Vec<&'a str>, String) {
    let Some(start) = lines.iter().position(|l| l.starts_with('|')) else {
        return (Vec::new(), String::new());
    };
    let rows = lines[start..]
        .iter()
        .take_while(|l| l.starts_with('|'))
        .map(|l| l.trim_end())
        .collect();
    let before = &lines[..start];
    let para_start = before
        .iter()
        .rposition(|l| !l.trim().is_empty())
        .map_or(0, |last| {
            before[..last]
                .iter()
                .rposition(|l| l.trim().is_empty())
                .map_or(0, |blank| blank + 1)
        });
    let intro = before[para_start..]
        .iter()
        .flat_map(|l| l.split_whitespace())
        .collect::<Vec<_>>()
        .join(" ");
    (rows, intro)
}

/// README.md repeats the table for readers who never open the code: a copy that drifts
/// would tell them what the loader does not do.
#[test]
fn readme_repeats_the_mtl_table_of_load_mtl() {
    let (code_rows, code_intro) = table_and_intro(&module_doc(MTL_RS));
    let (readme_rows, readme_intro) = table_and_intro(&readme_section(README, "### MTL materials"));
    assert!(
        code_rows.len() > 2,
        "load/mtl.rs: no MTL table in its module doc"
    );
    let only = |rows: &[&str], other: &[&str]| -> Vec<String> {
        let v: Vec<String> = rows
            .iter()
            .filter(|r| !other.contains(r))
            .map(|r| format!("    {r}"))
            .collect();
        if v.is_empty() {
            vec!["    (none)".into()]
        } else {
            v
        }
    };
    let (only_readme, only_code) = (
        only(&readme_rows, &code_rows),
        only(&code_rows, &readme_rows),
    );
    let differ = if only_readme == only_code {
        "  the same rows in another order".to_string()
    } else {
        format!(
            "  rows only in README.md:\n{}\n  rows only in load/mtl.rs:\n{}",
            only_readme.join("\n"),
            only_code.join("\n")
        )
    };
    assert!(
        readme_rows == code_rows,
        "README.md's MTL table (`### MTL materials`) differs from the one in load/mtl.rs, the \
         one statement of the table: edit it there, then copy it to README.md.\n{differ}"
    );
    assert!(
        !code_intro.is_empty() && readme_intro == code_intro,
        "README.md's sentence before its MTL table differs from the one in load/mtl.rs, the \
         one statement of the table:\n  README.md:   {readme_intro}\n  load/mtl.rs: {code_intro}"
    );
}
