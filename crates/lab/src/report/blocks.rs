//! The report as a list of blocks, and its two renderings: Markdown and a self-contained HTML
//! page.

use std::fmt::Write as _;

/// A piece of the report.
pub enum Block {
    Heading(u8, String),
    /// A paragraph; `backticks` mark code.
    Para(String),
    Table(Vec<String>, Vec<Vec<String>>),
    /// Images side by side: (relative path, caption).
    Figures(Vec<(String, String)>),
}

/// Every relative link (images and plots) a list of blocks holds.
pub fn links(blocks: &[Block]) -> Vec<String> {
    blocks
        .iter()
        .flat_map(|b| match b {
            Block::Figures(f) => f.iter().map(|(p, _)| p.clone()).collect(),
            _ => Vec::new(),
        })
        .collect()
}

pub fn markdown(blocks: &[Block]) -> String {
    let mut s = String::new();
    for b in blocks {
        match b {
            Block::Heading(n, t) => {
                let _ = writeln!(s, "{} {t}\n", "#".repeat(*n as usize));
            }
            Block::Para(t) => {
                let _ = writeln!(s, "{t}\n");
            }
            Block::Table(head, rows) => {
                let _ = writeln!(s, "| {} |", head.join(" | "));
                let _ = writeln!(s, "|{}", "---|".repeat(head.len()));
                for r in rows {
                    let _ = writeln!(s, "| {} |", r.join(" | "));
                }
                s.push('\n');
            }
            Block::Figures(f) => {
                let cells: Vec<String> = f.iter().map(|(p, c)| format!("![{c}]({p})")).collect();
                let _ = writeln!(s, "{}\n", cells.join(" "));
                let caps: Vec<&str> = f.iter().map(|(_, c)| c.as_str()).collect();
                let _ = writeln!(s, "*{}*\n", caps.join(" · "));
            }
        }
    }
    s
}

fn escape(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Escaped text with `code` spans.
fn inline(t: &str) -> String {
    escape(t)
        .split('`')
        .enumerate()
        .map(|(i, p)| {
            if i % 2 == 1 {
                format!("<code>{p}</code>")
            } else {
                p.to_string()
            }
        })
        .collect()
}

pub fn html(title: &str, blocks: &[Block]) -> String {
    let mut s = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n\
         <style>\nbody {{ font-family: sans-serif; max-width: 1200px; margin: 2em auto; \
         padding: 0 1em; line-height: 1.45; color: #222; }}\n\
         table {{ border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }}\n\
         td, th {{ border: 1px solid #ccc; padding: 0.2em 0.5em; text-align: right; }}\n\
         td:first-child, th:first-child {{ text-align: left; }}\n\
         .figs {{ display: flex; flex-wrap: wrap; gap: 1em; }}\n\
         figure {{ margin: 0; display: table; }} figure img {{ max-width: 100%; image-rendering: pixelated; }}\n\
         figcaption {{ display: table-caption; caption-side: bottom; font-size: 0.85em; color: #555; }}\n\
         code {{ background: #f3f3f3; padding: 0 0.2em; }}\n</style>\n</head>\n<body>\n",
        escape(title)
    );
    for b in blocks {
        match b {
            Block::Heading(n, t) => {
                let _ = writeln!(s, "<h{n}>{}</h{n}>", inline(t));
            }
            Block::Para(t) => {
                let _ = writeln!(s, "<p>{}</p>", inline(t));
            }
            Block::Table(head, rows) => {
                s.push_str("<table>\n<tr>");
                for h in head {
                    let _ = write!(s, "<th>{}</th>", inline(h));
                }
                s.push_str("</tr>\n");
                for r in rows {
                    s.push_str("<tr>");
                    for c in r {
                        let _ = write!(s, "<td>{}</td>", inline(c));
                    }
                    s.push_str("</tr>\n");
                }
                s.push_str("</table>\n");
            }
            Block::Figures(f) => {
                s.push_str("<div class=\"figs\">\n");
                for (p, c) in f {
                    let _ = writeln!(
                        s,
                        "<figure><a href=\"{p}\"><img src=\"{p}\" alt=\"{a}\"></a>\
                         <figcaption>{c}</figcaption></figure>",
                        p = escape(p),
                        a = escape(c),
                        c = inline(c)
                    );
                }
                s.push_str("</div>\n");
            }
        }
    }
    s.push_str("</body>\n</html>\n");
    s
}
