//! Reading `ipc/PROTOCOL.md`'s tables, for the tests that check the document against the
//! code (`ipc/tests/protocol_doc.rs`, and the daemon's limits in `tests/protocol_limits.rs`).

use std::collections::BTreeMap;

/// The protocol document's text (`ipc/PROTOCOL.md`, found from this file whichever crate's
/// test includes it).
#[must_use]
pub fn document() -> &'static str {
    include_str!("../../PROTOCOL.md")
}

/// The first table after the first heading line that starts with `heading`: its rows
/// (header and separator left out), each a list of cells, trimmed, backticks removed.
///
/// # Panics
/// No such heading, or no table under it before the next heading.
#[must_use]
pub fn table_under(doc: &str, heading: &str) -> Vec<Vec<String>> {
    let mut lines = doc.lines().skip_while(|l| !l.starts_with(heading));
    assert!(
        lines.next().is_some(),
        "PROTOCOL.md has no heading `{heading}`"
    );
    let rows: Vec<Vec<String>> = lines
        .take_while(|l| !l.starts_with('#'))
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .map(|l| {
            l.trim()
                .trim_matches('|')
                .split('|')
                .map(|c| c.trim().replace('`', ""))
                .collect()
        })
        .collect();
    assert!(
        !rows.is_empty(),
        "no table under `{heading}` in PROTOCOL.md"
    );
    rows
}

/// A two-column table under `heading` as a map from the first column to `column`.
///
/// # Panics
/// As [`table_under`], or a key appears twice.
#[must_use]
pub fn map_under(doc: &str, heading: &str, column: usize) -> BTreeMap<String, String> {
    let mut map = BTreeMap::new();
    for row in table_under(doc, heading) {
        let old = map.insert(row[0].clone(), row[column].clone());
        assert!(
            old.is_none(),
            "`{}` is listed twice under `{heading}`",
            row[0]
        );
    }
    map
}

/// A number as the document writes it: digits with optional `,` thousands separators, or
/// `1eN`.
///
/// # Panics
/// Not a number.
#[must_use]
pub fn number(text: &str) -> f64 {
    let first = text.split_whitespace().next().unwrap_or("");
    first
        .replace(',', "")
        .parse()
        .unwrap_or_else(|_| panic!("`{text}` is not a number"))
}
