//! The scene language's vocabulary: reserved words, each shape's parameters and an
//! example of it, and the closest known word to a typo.

use super::{GROUPS, MODIFIERS, SETTINGS, SHAPES};

/// The closest of `known` to `word` (Levenshtein), when close enough to be a typo.
#[must_use]
pub(crate) fn closest<'a>(word: &str, known: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let w = word.to_ascii_lowercase();
    let mut best: Option<(usize, &str)> = None;
    for k in known {
        let d = levenshtein(&w, k);
        if best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, k));
        }
    }
    let (d, k) = best?;
    let limit = (w.chars().count().max(k.len()) / 3).max(1);
    (d <= limit && d < w.chars().count().max(1)).then_some(k)
}

/// The optimal-string-alignment distance: insertions, deletions, substitutions and
/// transpositions of neighbours each cost one.
fn levenshtein(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, v) in d[0].iter_mut().enumerate() {
        *v = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[i - 1][j - 1] + cost)
                .min(d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = v;
        }
    }
    d[a.len()][b.len()]
}

pub(super) fn statement_words() -> Vec<&'static str> {
    SHAPES
        .iter()
        .chain(GROUPS)
        .chain(SETTINGS)
        .chain(&["let"])
        .copied()
        .collect()
}

pub(super) fn is_reserved(w: &str) -> bool {
    statement_words().contains(&w) || MODIFIERS.contains(&w) || w == "pi"
}

/// The parameter names each shape takes.
pub(super) fn params_of(shape: &str) -> &'static [&'static str] {
    match shape {
        "sphere" => &["r"],
        "box" | "prism" => &["size"],
        "ellipsoid" | "spheroid" => &["r"],
        "cylinder" => &["r", "h"],
        "cone" => &["r1", "r2", "h"],
        "torus" => &["major", "minor"],
        "capsule" => &["r", "h"],
        "halfspace" => &["normal", "offset"],
        "polyhedron" => &["planes"],
        _ => &[],
    }
}

pub(super) fn example_of(shape: &str) -> &'static str {
    match shape {
        "sphere" => "sphere(r = 10)",
        "box" | "prism" => "box(size = [20, 10, 5])",
        "ellipsoid" | "spheroid" => "ellipsoid(r = [20, 10, 5])",
        "cylinder" => "cylinder(r = 5, h = 20)",
        "cone" => "cone(r1 = 10, r2 = 4, h = 20)",
        "torus" => "torus(major = 20, minor = 5)",
        "capsule" => "capsule(r = 5, h = 20)",
        "halfspace" => "halfspace(normal = [0, 0, 1], offset = 0)",
        _ => "polyhedron(planes = [[1, 0, 0, 5], [-1, 0, 0, 5], ...])",
    }
}
