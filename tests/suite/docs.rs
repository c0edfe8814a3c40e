//! The docs against the code: the book's table of glTF extensions is `GLTF_EXTENSIONS`, every
//! TOML snippet in README.md and the book (docs/src/) parses, every one fenced `toml,scene`
//! loads as a whole scene, and every relative link points at a file that exists.

use glint::scene::mesh::{ExtensionSupport, GLTF_EXTENSIONS};
use glint::scene::Scene;
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// README.md and every page of the book.
fn pages() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let mut pages = vec![root().join("README.md")];
    walk(&root().join("docs/src"), &mut pages);
    pages.sort();
    pages
}

/// The fenced code blocks of a Markdown page: (info string, first line number, text).
fn code_blocks(text: &str) -> Vec<(String, usize, String)> {
    let mut blocks = Vec::new();
    let mut open: Option<(String, usize, String)> = None;
    for (i, line) in text.lines().enumerate() {
        let fence = line.trim_start().strip_prefix("```");
        match (&mut open, fence) {
            (None, Some(info)) => open = Some((info.trim().to_owned(), i + 2, String::new())),
            (Some(_), Some(_)) => blocks.push(open.take().unwrap()),
            (Some((_, _, body)), None) => {
                body.push_str(line);
                body.push('\n');
            }
            (None, None) => {}
        }
    }
    assert!(open.is_none(), "a code block is not closed");
    blocks
}

#[test]
fn the_books_gltf_extension_table_is_the_codes() {
    let page = root().join("docs/src/reference/meshes.md");
    let text = std::fs::read_to_string(&page).unwrap();
    let table = text
        .split("<!-- gltf-extensions:begin -->")
        .nth(1)
        .and_then(|rest| rest.split("<!-- gltf-extensions:end -->").next())
        .expect("the table's markers");
    let rows: Vec<Vec<String>> = table
        .lines()
        .filter(|l| l.starts_with('|'))
        .skip(2)
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|cell| cell.trim().to_owned())
                .collect()
        })
        .collect();
    // What the table should say, to paste into the page where it differs.
    let expected: Vec<String> = GLTF_EXTENSIONS
        .iter()
        .map(|(name, support)| match support {
            ExtensionSupport::Fully => format!("| `{name}` | fully | … |"),
            ExtensionSupport::InPart(what) => format!("| `{name}` | in part | {what} |"),
        })
        .collect();
    let expected = expected.join("\n");
    assert_eq!(
        rows.len(),
        GLTF_EXTENSIONS.len(),
        "expected rows:\n{expected}"
    );
    for (row, (name, support)) in rows.iter().zip(GLTF_EXTENSIONS) {
        assert_eq!(row[0], format!("`{name}`"), "expected rows:\n{expected}");
        match support {
            // A fully read extension's third column may hold a note.
            ExtensionSupport::Fully => assert_eq!(row[1], "fully", "{name}"),
            ExtensionSupport::InPart(what) => {
                assert_eq!(
                    (row[1].as_str(), row[2].as_str()),
                    ("in part", *what),
                    "{name}"
                )
            }
        }
    }
}

#[test]
fn every_toml_snippet_parses_and_every_scene_snippet_loads() {
    let mut scenes = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for (info, line, body) in code_blocks(&text) {
            let at = format!("{}:{line}", page.display());
            let mut words = info.split(',').map(str::trim);
            if words.next() != Some("toml") {
                continue;
            }
            if let Err(e) = body.parse::<toml::Table>() {
                panic!("{at}: not TOML: {e}");
            }
            if words.any(|w| w == "scene") {
                // Paths in a scene snippet are relative to the repository's root.
                Scene::parse(&body, &root().join("snippet.toml"))
                    .unwrap_or_else(|e| panic!("{at}: the scene does not load: {e}"));
                scenes += 1;
            }
        }
    }
    assert!(scenes >= 1, "no toml,scene snippet found");
}

#[test]
fn every_relative_link_points_at_a_file() {
    let mut broken = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        // Links outside code blocks: `](target)`.
        let mut in_code = false;
        for (i, line) in text.lines().enumerate() {
            if line.trim_start().starts_with("```") {
                in_code = !in_code;
                continue;
            }
            if in_code {
                continue;
            }
            for part in line.split("](").skip(1) {
                let Some(target) = part.split(')').next() else {
                    continue;
                };
                let target = target.split('#').next().unwrap().trim();
                if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                let path = page.parent().unwrap().join(target);
                if !path.exists() {
                    broken.push(format!("{}:{}: {target}", page.display(), i + 1));
                }
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}
