//! The scene text format (`.tss`, "tesseral scene") and its parser. The format is
//! documented, with its grammar and an example of every construct, in
//! `docs/scenes.md`.
//!
//! ```
//! use tesseral::csg::Scene;
//! let src = "depth 5\nlet r = 8\nsphere(r = r) at [16, 16, 16] colour \"red\"\n\
//!            bounds [0, 0, 0] [32, 32, 32]\n";
//! let scene = Scene::parse(src, "ball.tss".as_ref()).unwrap();
//! let tree = scene.build().unwrap();
//! assert_eq!(tree.depth(), 5);
//! assert!(tree.contains([16, 16, 16]));
//! ```

use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use super::{Colour, Csg, CsgError, Shape, Solid, Transform};
use crate::linear::LinearOctree;

/// The deepest tree a scene may ask for.
pub const MAX_SCENE_DEPTH: u8 = 16;
/// The most primitives a scene may hold.
pub const MAX_PRIMITIVES: usize = 10_000;
/// The deepest nesting of groups and brackets.
pub const MAX_NESTING: usize = 64;
/// The largest scene file, in bytes.
pub const MAX_SCENE_BYTES: usize = 4 << 20;
/// The most numbers and lists one value may hold, counted through shared `let`
/// names: `[a, a]` holds `a` twice.
pub const MAX_VALUE_ELEMENTS: usize = 1 << 20;
/// The most numbers and lists the whole scene may build while it is evaluated (list
/// literals and arithmetic on lists), so that a short file cannot ask for unbounded
/// work by repeating a large computation.
pub const MAX_SCENE_WORK: usize = 1 << 24;

/// How many characters of a source line a diagnostic shows, and how many of them
/// come before the fault.
const SHOWN_CHARS: usize = 120;
const SHOWN_BEFORE: usize = 40;

/// The shapes a scene may name.
pub const SHAPES: &[&str] = &[
    "box",
    "prism",
    "sphere",
    "ellipsoid",
    "spheroid",
    "cylinder",
    "cone",
    "torus",
    "capsule",
    "halfspace",
    "polyhedron",
];
/// The set operations a scene may name.
pub const GROUPS: &[&str] = &["union", "intersection", "difference", "not"];
/// The settings.
pub const SETTINGS: &[&str] = &["depth", "voxel", "bounds"];
/// The modifiers that may follow a solid.
pub const MODIFIERS: &[&str] = &["at", "rotate", "scale", "colour", "color"];

/// A located error in a scene file: `file:line:column`, the line itself with a caret
/// under the fault, and a hint.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// The file.
    pub path: PathBuf,
    /// The line, from 1.
    pub line: usize,
    /// The column, from 1 (in characters).
    pub column: usize,
    /// The width of the fault, in characters (at least 1).
    pub width: usize,
    /// What is wrong.
    pub message: String,
    /// How to fix it, when we can tell (for a misspelled name: the closest known one).
    pub hint: Option<String>,
    /// The text of the line at fault.
    pub source_line: String,
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}:{}: {}",
            self.path.display(),
            self.line,
            self.column,
            self.message
        )?;
        let num = self.line.to_string();
        let pad = " ".repeat(num.len());
        // A hostile line can be megabytes long: show a window of it around the fault.
        let skip = self.column.saturating_sub(1 + SHOWN_BEFORE);
        let shown: String = self
            .source_line
            .chars()
            .skip(skip)
            .take(SHOWN_CHARS)
            .collect();
        let (cut, under_cut) = if skip > 0 { ("…", " ") } else { ("", "") };
        write!(f, "\n{pad} |\n{num} | {cut}{shown}\n{pad} | {under_cut}")?;
        let col = self.column.saturating_sub(1) - skip;
        write!(
            f,
            "{}{}",
            " ".repeat(col),
            "^".repeat(self.width.clamp(1, SHOWN_CHARS.saturating_sub(col).max(1)))
        )?;
        if let Some(h) = &self.hint {
            write!(f, "\n{pad} = hint: {h}")?;
        }
        Ok(())
    }
}

/// What can go wrong reading a scene.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The file could not be read.
    #[error("{path}: {source}", path = .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The text is malformed or meaningless at a located place.
    #[error("{0}")]
    Parse(Box<Diagnostic>),
    /// The scene parsed but its octree cannot be built (too many leaves).
    #[error("{path}: {source}", path = .path.display())]
    Build {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: CsgError,
    },
}

impl SceneError {
    /// The diagnostic, for a parse error.
    #[must_use]
    pub fn diagnostic(&self) -> Option<&Diagnostic> {
        match self {
            SceneError::Parse(d) => Some(d),
            _ => None,
        }
    }
}

/// A parsed scene: the solid in world units and the voxel space it is built in.
///
/// The space is the cube of `2^depth` voxels of side `voxel` whose lowest corner is
/// `bounds_min`; in voxel coordinates (those of the octree, origin `[0, 0, 0]`) a world
/// point `p` is `(p − bounds_min) / voxel`.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The union of the scene's objects, in world units, each with its colour.
    pub solid: Solid,
    /// The tree depth.
    pub depth: u8,
    /// The side of a voxel, in world units.
    pub voxel: f64,
    /// The world position of the space's lowest corner.
    pub bounds_min: [f64; 3],
    /// The number of top-level objects.
    pub objects: usize,
    pub(super) path: PathBuf,
}

impl Scene {
    /// Reads and parses a scene file.
    ///
    /// # Errors
    /// [`SceneError::Io`], or [`SceneError::Parse`] located in the file.
    pub fn read(path: &Path) -> Result<Scene, SceneError> {
        let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
            path: path.to_owned(),
            source,
        })?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let upto = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            let text = String::from_utf8_lossy(upto).into_owned();
            let line = text.matches('\n').count() + 1;
            let col = text.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            SceneError::Parse(Box::new(Diagnostic {
                path: path.to_owned(),
                line,
                column: col,
                width: 1,
                message: "the file is not valid UTF-8".into(),
                hint: Some("save the scene as UTF-8 text".into()),
                source_line: text.rsplit('\n').next().unwrap_or("").to_owned(),
            }))
        })?;
        Self::parse(&text, path)
    }

    /// Parses scene text; `path` names the file in error messages.
    ///
    /// # Errors
    /// [`SceneError::Parse`] with the line, column, a caret and a hint.
    pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
        let mut p = Parser::new(text, path)?;
        p.file()
    }

    /// The map from world to voxel coordinates.
    #[must_use]
    pub fn world_to_voxel(&self) -> Transform {
        let s = 1.0 / self.voxel;
        Transform {
            scale: s,
            at: self.bounds_min.map(|b| -b * s),
            ..Transform::IDENTITY
        }
    }

    /// The solid compiled in voxel coordinates (the octree's).
    ///
    /// # Errors
    /// [`SceneError::Build`] (cannot happen for a parsed scene, whose solids are checked).
    pub fn csg(&self) -> Result<Csg, SceneError> {
        self.solid
            .clone()
            .transform(self.world_to_voxel())
            .compile()
            .map_err(|source| SceneError::Build {
                path: self.path.clone(),
                source,
            })
    }

    /// Builds the scene's octree: depth [`Scene::depth`], origin `[0, 0, 0]`.
    ///
    /// # Errors
    /// [`SceneError::Build`] when the tree would exceed the leaf limit.
    pub fn build(&self) -> Result<LinearOctree, SceneError> {
        self.csg()?
            .build(self.depth, [0, 0, 0])
            .map_err(|source| SceneError::Build {
                path: self.path.clone(),
                source,
            })
    }
}

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

// ---------------------------------------------------------------- tokens

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Ident(String),
    Num(f64),
    Str(String),
    Punct(char),
    Eof,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Span {
    line: usize,
    col: usize,
    width: usize,
}

#[derive(Debug, Clone)]
struct Token {
    tok: Tok,
    span: Span,
}

fn describe(t: &Tok) -> String {
    match t {
        Tok::Ident(s) => format!("`{s}`"),
        Tok::Num(n) => format!("the number {n}"),
        Tok::Str(s) => format!("the string \"{s}\""),
        Tok::Punct(c) => format!("`{c}`"),
        Tok::Eof => "the end of the file".into(),
    }
}

/// A value of the scene language. Lists are shared, not copied: a `let` name used
/// twice costs one pointer, which is what keeps `let b = [a, a, a]` cheap; what a
/// value *would* cost if expanded is kept in `List::elements` and budgeted.
#[derive(Debug, Clone, PartialEq)]
enum Value {
    Num(f64),
    List(Rc<List>),
}

#[derive(Debug, PartialEq)]
struct List {
    items: Vec<Value>,
    /// The numbers and lists this list holds, itself included, counted through
    /// sharing.
    elements: usize,
    /// Lists inside lists: `[1]` has depth 1.
    depth: usize,
}

impl std::ops::Deref for List {
    type Target = [Value];
    fn deref(&self) -> &[Value] {
        &self.items
    }
}

impl Value {
    fn elements(&self) -> usize {
        match self {
            Value::Num(_) => 1,
            Value::List(l) => l.elements,
        }
    }

    fn depth(&self) -> usize {
        match self {
            Value::Num(_) => 0,
            Value::List(l) => l.depth,
        }
    }
}

struct Parser<'a> {
    path: &'a Path,
    lines: Vec<&'a str>,
    toks: Vec<Token>,
    pos: usize,
    lets: HashMap<String, (Value, usize)>,
    prims: usize,
    nesting: usize,
    /// Numbers and lists built so far, against [`MAX_SCENE_WORK`].
    work: usize,
}

struct Settings {
    depth: Option<(u8, Span)>,
    voxel: Option<(f64, Span)>,
    bounds: Option<([f64; 3], [f64; 3], Span)>,
}

impl<'a> Parser<'a> {
    fn new(text: &'a str, path: &'a Path) -> Result<Self, SceneError> {
        let mut p = Parser {
            path,
            lines: text.split('\n').map(|l| l.trim_end_matches('\r')).collect(),
            toks: Vec::new(),
            pos: 0,
            lets: HashMap::new(),
            prims: 0,
            nesting: 0,
            work: 0,
        };
        if text.len() > MAX_SCENE_BYTES {
            return Err(p.err(
                Span {
                    line: 1,
                    col: 1,
                    width: 1,
                },
                format!("the scene is larger than {MAX_SCENE_BYTES} bytes"),
                Some("split it or generate the octree another way".into()),
            ));
        }
        p.tokenize(text)?;
        Ok(p)
    }

    fn err(&self, span: Span, message: impl Into<String>, hint: Option<String>) -> SceneError {
        let source_line = self
            .lines
            .get(span.line.wrapping_sub(1))
            .copied()
            .unwrap_or("")
            .to_owned();
        SceneError::Parse(Box::new(Diagnostic {
            path: self.path.to_owned(),
            line: span.line,
            column: span.col,
            width: span.width.max(1),
            message: message.into(),
            hint,
            source_line,
        }))
    }

    fn tokenize(&mut self, text: &str) -> Result<(), SceneError> {
        for (li, line) in text.split('\n').enumerate() {
            let chars: Vec<char> = line.trim_end_matches('\r').chars().collect();
            let mut i = 0;
            while i < chars.len() {
                let c = chars[i];
                let start = i;
                let span = |end: usize| Span {
                    line: li + 1,
                    col: start + 1,
                    width: end - start,
                };
                if c == '#' {
                    break;
                } else if c.is_whitespace() {
                    i += 1;
                } else if c.is_ascii_alphabetic() || c == '_' {
                    while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                        i += 1;
                    }
                    let word: String = chars[start..i].iter().collect();
                    self.toks.push(Token {
                        tok: Tok::Ident(word),
                        span: span(i),
                    });
                } else if c.is_ascii_digit()
                    || (c == '.' && chars.get(i + 1).is_some_and(char::is_ascii_digit))
                {
                    while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                        i += 1;
                    }
                    if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                        let mut j = i + 1;
                        if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                            j += 1;
                        }
                        if j < chars.len() && chars[j].is_ascii_digit() {
                            i = j;
                            while i < chars.len() && chars[i].is_ascii_digit() {
                                i += 1;
                            }
                        }
                    }
                    if i < chars.len() && (chars[i].is_ascii_alphabetic() || chars[i] == '_') {
                        while i < chars.len() && chars[i].is_ascii_alphanumeric() {
                            i += 1;
                        }
                        let s: String = chars[start..i].iter().collect();
                        return Err(self.err(
                            span(i),
                            format!("`{s}` is not a number"),
                            Some("numbers look like 12, 0.5 or 1e3; units are not written".into()),
                        ));
                    }
                    let s: String = chars[start..i].iter().collect();
                    let Ok(v) = s.parse::<f64>() else {
                        return Err(self.err(
                            span(i),
                            format!("`{s}` is not a number"),
                            Some("a number has at most one decimal point".into()),
                        ));
                    };
                    self.toks.push(Token {
                        tok: Tok::Num(v),
                        span: span(i),
                    });
                } else if c == '"' {
                    i += 1;
                    while i < chars.len() && chars[i] != '"' {
                        i += 1;
                    }
                    if i >= chars.len() {
                        return Err(self.err(
                            span(chars.len()),
                            "unterminated string",
                            Some("close the string with `\"` on the same line".into()),
                        ));
                    }
                    i += 1;
                    let s: String = chars[start + 1..i - 1].iter().collect();
                    self.toks.push(Token {
                        tok: Tok::Str(s),
                        span: span(i),
                    });
                } else if "[](){},=+-*/".contains(c) {
                    i += 1;
                    self.toks.push(Token {
                        tok: Tok::Punct(c),
                        span: span(i),
                    });
                } else {
                    return Err(self.err(
                        span(i + 1),
                        format!("unexpected character `{c}`"),
                        Some("comments start with `#`".into()),
                    ));
                }
            }
        }
        let last = self.lines.len().max(1);
        let col = self.lines.last().map_or(0, |l| l.chars().count()) + 1;
        self.toks.push(Token {
            tok: Tok::Eof,
            span: Span {
                line: last,
                col,
                width: 1,
            },
        });
        Ok(())
    }

    fn peek(&self) -> &Token {
        &self.toks[self.pos]
    }

    fn next(&mut self) -> Token {
        let t = self.toks[self.pos].clone();
        if self.pos + 1 < self.toks.len() {
            self.pos += 1;
        }
        t
    }

    fn is_punct(&self, c: char) -> bool {
        self.peek().tok == Tok::Punct(c)
    }

    fn expect(&mut self, c: char, hint: &str) -> Result<Token, SceneError> {
        let t = self.next();
        if t.tok == Tok::Punct(c) {
            Ok(t)
        } else {
            Err(self.err(
                t.span,
                format!("expected `{c}`, found {}", describe(&t.tok)),
                Some(hint.into()),
            ))
        }
    }

    fn enter(&mut self, span: Span) -> Result<(), SceneError> {
        self.nesting += 1;
        if self.nesting > MAX_NESTING {
            return Err(self.err(
                span,
                format!("nesting deeper than {MAX_NESTING}"),
                Some("flatten the groups or brackets".into()),
            ));
        }
        Ok(())
    }

    // ------------------------------------------------------------ statements

    fn file(&mut self) -> Result<Scene, SceneError> {
        let mut settings = Settings {
            depth: None,
            voxel: None,
            bounds: None,
        };
        let mut objects: Vec<(Solid, Span)> = Vec::new();
        loop {
            let t = self.peek().clone();
            match &t.tok {
                Tok::Eof => break,
                Tok::Ident(w) if w == "depth" => {
                    self.next();
                    let (v, span) = self.expr_span()?;
                    let d = self.num(&v, span, "depth")?;
                    if d.fract() != 0.0 || !(1.0..=f64::from(MAX_SCENE_DEPTH)).contains(&d) {
                        return Err(self.err(
                            span,
                            format!(
                                "depth must be a whole number from 1 to {MAX_SCENE_DEPTH}, got {d}"
                            ),
                            Some("depth D gives 2^D voxels per axis; 6 to 10 is typical".into()),
                        ));
                    }
                    self.once(settings.depth.map(|x| x.1), t.span, "depth")?;
                    settings.depth = Some((d as u8, t.span));
                }
                Tok::Ident(w) if w == "voxel" => {
                    self.next();
                    let (v, span) = self.expr_span()?;
                    let s = self.num(&v, span, "voxel")?;
                    if !(s.is_finite() && s > 0.0) {
                        return Err(self.err(
                            span,
                            format!("the voxel size must be positive, got {s}"),
                            Some("`voxel 0.5` makes voxels half a unit wide".into()),
                        ));
                    }
                    self.once(settings.voxel.map(|x| x.1), t.span, "voxel")?;
                    settings.voxel = Some((s, t.span));
                }
                Tok::Ident(w) if w == "bounds" => {
                    self.next();
                    let (lo, lspan) = self.expr_span()?;
                    let lo = self.vec3(&lo, lspan, "bounds")?;
                    let (hi, hspan) = self.expr_span()?;
                    let hi = self.vec3(&hi, hspan, "bounds")?;
                    if (0..3).any(|a| hi[a] <= lo[a]) {
                        return Err(self.err(
                            hspan,
                            "the upper corner of `bounds` must exceed the lower one on every axis",
                            Some("write `bounds [xmin, ymin, zmin] [xmax, ymax, zmax]`".into()),
                        ));
                    }
                    self.once(settings.bounds.map(|x| x.2), t.span, "bounds")?;
                    settings.bounds = Some((lo, hi, t.span));
                }
                Tok::Ident(w) if w == "let" => {
                    self.let_statement()?;
                }
                _ => {
                    let start = t.span;
                    let solid = self.solid()?;
                    objects.push((solid, start));
                }
            }
        }
        self.finish(settings, objects)
    }

    fn once(&self, prev: Option<Span>, span: Span, what: &str) -> Result<(), SceneError> {
        match prev {
            Some(p) => Err(self.err(
                span,
                format!("`{what}` is set twice"),
                Some(format!("it was first set on line {}; keep one", p.line)),
            )),
            None => Ok(()),
        }
    }

    fn let_statement(&mut self) -> Result<(), SceneError> {
        let kw = self.next();
        let name = self.next();
        let Tok::Ident(n) = &name.tok else {
            return Err(self.err(
                name.span,
                format!("expected a name after `let`, found {}", describe(&name.tok)),
                Some("write `let name = value`".into()),
            ));
        };
        if is_reserved(n) {
            return Err(self.err(
                name.span,
                format!("`{n}` is a reserved word and cannot be a parameter name"),
                Some("choose another name".into()),
            ));
        }
        if let Some((_, line)) = self.lets.get(n) {
            return Err(self.err(
                name.span,
                format!("`{n}` is already defined"),
                Some(format!(
                    "it was defined on line {line}; choose another name"
                )),
            ));
        }
        self.expect('=', "write `let name = value`")?;
        let v = self.expr()?;
        self.lets.insert(n.clone(), (v, kw.span.line));
        Ok(())
    }

    fn solid(&mut self) -> Result<Solid, SceneError> {
        let t = self.next();
        let Tok::Ident(word) = &t.tok else {
            return Err(self.err(
                t.span,
                format!(
                    "expected a shape, a group or a setting, found {}",
                    describe(&t.tok)
                ),
                Some(format!(
                    "a statement starts with one of: {}",
                    statement_words().join(", ")
                )),
            ));
        };
        let base = if SHAPES.contains(&word.as_str()) {
            self.primitive(word, t.span)?
        } else if GROUPS.contains(&word.as_str()) {
            self.group(word, t.span)?
        } else {
            let hint = match closest(word, statement_words()) {
                Some(s) => format!("did you mean `{s}`?"),
                None => format!(
                    "a statement starts with one of: {}",
                    statement_words().join(", ")
                ),
            };
            let what = if MODIFIERS.contains(&word.as_str()) {
                format!("`{word}` must follow a solid")
            } else {
                format!("unknown shape or keyword `{word}`")
            };
            return Err(self.err(t.span, what, Some(hint)));
        };
        self.modifiers(base)
    }

    fn modifiers(&mut self, base: Solid) -> Result<Solid, SceneError> {
        let mut at: Option<[f64; 3]> = None;
        let mut rot: Option<[f64; 3]> = None;
        let mut scale: Option<f64> = None;
        let mut colour: Option<Colour> = None;
        let mut seen: HashMap<&'static str, usize> = HashMap::new();
        loop {
            let t = self.peek().clone();
            let Tok::Ident(w) = &t.tok else { break };
            let key: &'static str = match w.as_str() {
                "at" => "at",
                "rotate" => "rotate",
                "scale" => "scale",
                "colour" | "color" => "colour",
                _ => break,
            };
            self.next();
            if let Some(line) = seen.insert(key, t.span.line) {
                return Err(self.err(
                    t.span,
                    format!("`{key}` is given twice for one solid"),
                    Some(format!(
                        "it was first given on line {line}; wrap the solid in `union {{ ... }}` to apply another"
                    )),
                ));
            }
            match key {
                "at" => {
                    let (v, s) = self.expr_span()?;
                    at = Some(self.vec3(&v, s, "at")?);
                }
                "rotate" => {
                    let (v, s) = self.expr_span()?;
                    rot = Some(self.vec3(&v, s, "rotate")?);
                }
                "scale" => {
                    let (v, s) = self.expr_span()?;
                    let k = self.num(&v, s, "scale")?;
                    if !(k.is_finite() && k > 0.0) {
                        return Err(self.err(
                            s,
                            format!("the scale must be positive, got {k}"),
                            Some("`scale 2` doubles the size".into()),
                        ));
                    }
                    scale = Some(k);
                }
                _ => colour = Some(self.colour()?),
            }
        }
        let mut solid = base;
        if let Some(s) = scale {
            solid = solid.scaled(s);
        }
        if let Some(r) = rot {
            solid = solid.rotate(r);
        }
        if let Some(a) = at {
            solid = solid.at(a);
        }
        if let Some(c) = colour {
            solid = solid.colour(c);
        }
        Ok(solid)
    }

    fn colour(&mut self) -> Result<Colour, SceneError> {
        let t = self.peek().clone();
        if let Tok::Str(s) = &t.tok {
            self.next();
            return Colour::parse(s).ok_or_else(|| {
                let hint = if s.starts_with('#') {
                    "write six hex digits, as in \"#ff8800\"".to_owned()
                } else {
                    match closest(s, Colour::NAMED.iter().map(|(n, _)| *n)) {
                        Some(n) => format!("did you mean \"{n}\"?"),
                        None => {
                            "use a colour name such as \"red\", \"#rrggbb\" or [r, g, b]".into()
                        }
                    }
                };
                self.err(t.span, format!("unknown colour \"{s}\""), Some(hint))
            });
        }
        let (v, span) = self.expr_span()?;
        let c = self.vec3(&v, span, "colour")?;
        if c.iter().any(|x| !(0.0..=255.0).contains(x)) {
            return Err(self.err(
                span,
                "colour components must lie in 0..=255",
                Some("write [r, g, b] with each from 0 to 255".into()),
            ));
        }
        Ok(Colour(c.map(|x| x.round() as u8)))
    }

    fn group(&mut self, word: &str, span: Span) -> Result<Solid, SceneError> {
        self.enter(span)?;
        self.expect('{', &format!("write `{word} {{ ... }}`"))?;
        let mut parts = Vec::new();
        while !self.is_punct('}') {
            if self.peek().tok == Tok::Eof {
                let e = self.peek().span;
                return Err(self.err(
                    e,
                    format!("the `{word}` group is not closed"),
                    Some(format!(
                        "add `}}` to close the group opened on line {}",
                        span.line
                    )),
                ));
            }
            if let Tok::Ident(w) = &self.peek().tok {
                if SETTINGS.contains(&w.as_str()) || w == "let" {
                    let s = self.peek().span;
                    return Err(self.err(
                        s,
                        format!("`{w}` is only allowed at the top level"),
                        Some("move it out of the group, before the solids".into()),
                    ));
                }
            }
            parts.push(self.solid()?);
        }
        self.next();
        self.nesting -= 1;
        let need = match word {
            "not" => Some(1..=1),
            _ => Some(1..=usize::MAX),
        };
        if let Some(range) = need {
            if !range.contains(&parts.len()) {
                let msg = if word == "not" {
                    format!("`not` takes exactly one solid, got {}", parts.len())
                } else {
                    format!("the `{word}` group is empty")
                };
                let hint = if word == "not" {
                    "wrap several solids in `union { ... }` inside `not`"
                } else {
                    "put at least one solid between the braces"
                };
                return Err(self.err(span, msg, Some(hint.into())));
            }
        }
        Ok(match word {
            "union" => Solid::Union(parts),
            "intersection" => Solid::Intersection(parts),
            "difference" => Solid::Difference(parts),
            _ => Solid::Not(Box::new(parts.remove(0))),
        })
    }

    fn primitive(&mut self, word: &str, span: Span) -> Result<Solid, SceneError> {
        self.prims += 1;
        if self.prims > MAX_PRIMITIVES {
            return Err(self.err(
                span,
                format!("more than {MAX_PRIMITIVES} primitives"),
                Some("split the scene".into()),
            ));
        }
        self.expect('(', &format!("write `{word}(name = value, ...)`"))?;
        let mut args: Vec<(String, Value, Span, Span)> = Vec::new();
        let allowed = params_of(word);
        while !self.is_punct(')') {
            let t = self.next();
            let Tok::Ident(name) = &t.tok else {
                return Err(self.err(
                    t.span,
                    format!("expected a parameter name, found {}", describe(&t.tok)),
                    Some(format!("`{word}` takes: {}", allowed.join(", "))),
                ));
            };
            if !allowed.contains(&name.as_str()) {
                let hint = match closest(name, allowed.iter().copied()) {
                    Some(s) => {
                        format!("did you mean `{s}`? `{word}` takes: {}", allowed.join(", "))
                    }
                    None => format!("`{word}` takes: {}", allowed.join(", ")),
                };
                return Err(self.err(
                    t.span,
                    format!("`{word}` has no parameter `{name}`"),
                    Some(hint),
                ));
            }
            if args.iter().any(|a| &a.0 == name) {
                return Err(self.err(
                    t.span,
                    format!("parameter `{name}` is given twice"),
                    Some("keep one".into()),
                ));
            }
            self.expect('=', &format!("write `{name} = value`"))?;
            let (v, vs) = self.expr_span()?;
            args.push((name.clone(), v, t.span, vs));
            if !self.is_punct(')') {
                self.expect(',', "separate parameters with `,`")?;
            }
        }
        let close = self.next();
        let shape = self.make_shape(word, span, close.span, &args)?;
        if let Err(msg) = shape.validate() {
            return Err(self.err(span, format!("invalid `{word}`: {msg}"), None));
        }
        Ok(Solid::Primitive(shape))
    }

    fn make_shape(
        &self,
        word: &str,
        span: Span,
        close: Span,
        args: &[(String, Value, Span, Span)],
    ) -> Result<Shape, SceneError> {
        let get = |name: &str| args.iter().find(|a| a.0 == name);
        let need = |name: &str| {
            get(name).ok_or_else(|| {
                self.err(
                    close,
                    format!("`{word}` needs the parameter `{name}`"),
                    Some(format!("for example: {}", example_of(word))),
                )
            })
        };
        let positive = |a: &(String, Value, Span, Span), v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(self.err(
                    a.3,
                    format!("`{}` must be positive, got {v}", a.0),
                    Some("sizes and radii are lengths greater than zero".into()),
                ))
            }
        };
        let scalar = |name: &str| -> Result<f64, SceneError> {
            let a = need(name)?;
            let v = self.num(&a.1, a.3, name)?;
            positive(a, v)
        };
        // A number, or a list of `n` numbers.
        let spread = |name: &str, n: usize| -> Result<Vec<f64>, SceneError> {
            let a = need(name)?;
            let v = match &a.1 {
                Value::Num(x) => vec![*x; n],
                Value::List(_) => self.list(&a.1, a.3, name, n)?,
            };
            v.into_iter().map(|x| positive(a, x)).collect()
        };
        let shape = match word {
            "sphere" => Shape::Sphere { r: scalar("r")? },
            "box" | "prism" => {
                let s = spread("size", 3)?;
                Shape::cuboid([s[0], s[1], s[2]])
            }
            "ellipsoid" | "spheroid" => {
                let r = spread("r", 3)?;
                Shape::Ellipsoid {
                    r: [r[0], r[1], r[2]],
                }
            }
            "cylinder" => {
                let r = spread("r", 2)?;
                Shape::Cylinder {
                    r: [r[0], r[1]],
                    half_h: scalar("h")? / 2.0,
                }
            }
            "cone" => {
                let r1 = spread("r1", 2)?;
                let r2 = match get("r2") {
                    None => 0.0,
                    Some(a) => {
                        let v = self.num(&a.1, a.3, "r2")?;
                        if !(v.is_finite() && v >= 0.0) {
                            return Err(self.err(
                                a.3,
                                format!("`r2` must be zero or positive, got {v}"),
                                Some("r2 = 0 makes a pointed cone".into()),
                            ));
                        }
                        v
                    }
                };
                Shape::Cone {
                    r1: r1[0],
                    r2,
                    aspect: r1[1] / r1[0],
                    half_h: scalar("h")? / 2.0,
                }
            }
            "torus" => Shape::Torus {
                major: scalar("major")?,
                minor: scalar("minor")?,
            },
            "capsule" => {
                let r = scalar("r")?;
                let a = need("h")?;
                let h = self.num(&a.1, a.3, "h")?;
                if !(h.is_finite() && h >= 0.0) {
                    return Err(self.err(
                        a.3,
                        format!("`h` must be zero or positive, got {h}"),
                        Some("h is the distance between the centres of the end caps".into()),
                    ));
                }
                Shape::Capsule { r, half_h: h / 2.0 }
            }
            "halfspace" => {
                let a = need("normal")?;
                let n = self.vec3(&a.1, a.3, "normal")?;
                let offset = match get("offset") {
                    Some(o) => self.num(&o.1, o.3, "offset")?,
                    None => 0.0,
                };
                Shape::half_space(n, offset).ok_or_else(|| {
                    self.err(
                        a.3,
                        "the normal must not be zero",
                        Some("`normal = [0, 0, 1]` keeps the points below z = offset".into()),
                    )
                })?
            }
            "polyhedron" => {
                let a = need("planes")?;
                let Value::List(items) = &a.1 else {
                    return Err(self.err(
                        a.3,
                        "`planes` must be a list of [nx, ny, nz, d]",
                        Some("for example: planes = [[1, 0, 0, 5], [-1, 0, 0, 5], ...]".into()),
                    ));
                };
                if items.is_empty() {
                    return Err(self.err(
                        a.3,
                        "`planes` is empty",
                        Some(
                            "give at least four planes [nx, ny, nz, d] for a bounded solid".into(),
                        ),
                    ));
                }
                let mut planes = Vec::new();
                for it in items.iter() {
                    let v = self.list(it, a.3, "planes", 4)?;
                    planes.push([v[0], v[1], v[2], v[3]]);
                }
                Shape::polyhedron(&planes).ok_or_else(|| {
                    self.err(
                        a.3,
                        "a plane of `planes` has a zero normal",
                        Some("each plane [nx, ny, nz, d] keeps the points with n·p ≤ d".into()),
                    )
                })?
            }
            _ => unreachable!("params_of covers every shape"),
        };
        let _ = span;
        Ok(shape)
    }

    // ------------------------------------------------------------ values

    fn num(&self, v: &Value, span: Span, what: &str) -> Result<f64, SceneError> {
        match v {
            Value::Num(x) if x.is_finite() => Ok(*x),
            Value::Num(x) => Err(self.err(
                span,
                format!("`{what}` is not finite ({x})"),
                Some("check for a division by a tiny number".into()),
            )),
            Value::List(_) => Err(self.err(
                span,
                format!("`{what}` must be a number, not a list"),
                Some("remove the brackets".into()),
            )),
        }
    }

    fn list(&self, v: &Value, span: Span, what: &str, n: usize) -> Result<Vec<f64>, SceneError> {
        let example = match n {
            2 => "[a, b]",
            3 => "[x, y, z]",
            _ => "[nx, ny, nz, d]",
        };
        match v {
            Value::List(items) if items.len() == n => items
                .iter()
                .map(|x| match x {
                    Value::Num(f) if f.is_finite() => Ok(*f),
                    Value::Num(f) => Err(self.err(
                        span,
                        format!("`{what}` holds a number that is not finite ({f})"),
                        Some("check for an overflow such as 1e308 * 10, or inf - inf".into()),
                    )),
                    _ => Err(self.err(
                        span,
                        format!("`{what}` must hold {n} numbers"),
                        Some(format!("write {example}")),
                    )),
                })
                .collect(),
            Value::List(items) => Err(self.err(
                span,
                format!("`{what}` must hold {n} numbers, got {}", items.len()),
                Some(format!("write {example}")),
            )),
            Value::Num(_) => Err(self.err(
                span,
                format!("`{what}` must be a list of {n} numbers"),
                Some(format!("write {example}")),
            )),
        }
    }

    fn vec3(&self, v: &Value, span: Span, what: &str) -> Result<[f64; 3], SceneError> {
        let l = self.list(v, span, what, 3)?;
        Ok([l[0], l[1], l[2]])
    }

    fn expr_span(&mut self) -> Result<(Value, Span), SceneError> {
        let start = self.peek().span;
        let v = self.expr()?;
        let prev = self.toks[self.pos.saturating_sub(1)].span;
        let width = if prev.line == start.line && prev.col + prev.width > start.col {
            prev.col + prev.width - start.col
        } else {
            start.width
        };
        Ok((v, Span { width, ..start }))
    }

    fn expr(&mut self) -> Result<Value, SceneError> {
        let mut v = self.term()?;
        while self.is_punct('+') || self.is_punct('-') {
            let op = self.next();
            let r = self.term()?;
            v = self.arith(op, v, r)?;
        }
        Ok(v)
    }

    fn term(&mut self) -> Result<Value, SceneError> {
        let mut v = self.unary()?;
        while self.is_punct('*') || self.is_punct('/') {
            let op = self.next();
            let r = self.unary()?;
            v = self.arith(op, v, r)?;
        }
        Ok(v)
    }

    /// Unary minus, iteratively: a run of signs is any length without using the stack.
    fn unary(&mut self) -> Result<Value, SceneError> {
        let mut signs = Vec::new();
        while self.is_punct('-') {
            signs.push(self.next());
        }
        let mut v = self.atom()?;
        for op in signs.into_iter().rev() {
            v = self.arith(op, Value::Num(0.0), v)?;
        }
        Ok(v)
    }

    fn atom(&mut self) -> Result<Value, SceneError> {
        let t = self.next();
        match &t.tok {
            Tok::Num(v) => Ok(Value::Num(*v)),
            Tok::Ident(name) => {
                if name == "pi" {
                    return Ok(Value::Num(std::f64::consts::PI));
                }
                if let Some((v, _)) = self.lets.get(name) {
                    return Ok(v.clone());
                }
                let names: Vec<&str> = self.lets.keys().map(String::as_str).chain(["pi"]).collect();
                let hint = match closest(name, names.iter().copied()) {
                    Some(s) => format!("did you mean `{s}`?"),
                    None => format!("define it first with `let {name} = ...`"),
                };
                Err(self.err(t.span, format!("unknown name `{name}`"), Some(hint)))
            }
            Tok::Punct('(') => {
                self.enter(t.span)?;
                let v = self.expr()?;
                self.expect(')', "close the parenthesis")?;
                self.nesting -= 1;
                Ok(v)
            }
            Tok::Punct('[') => {
                self.enter(t.span)?;
                let mut items = Vec::new();
                while !self.is_punct(']') {
                    items.push(self.expr()?);
                    if items.len() > 4096 {
                        return Err(self.err(t.span, "a list longer than 4096 items", None));
                    }
                    if !self.is_punct(']') {
                        self.expect(',', "separate list items with `,` and close with `]`")?;
                    }
                }
                self.next();
                self.nesting -= 1;
                self.charge(items.len(), t.span)?;
                self.make_list(items, t.span)
            }
            Tok::Str(_) => Err(self.err(
                t.span,
                "a string is not allowed here",
                Some("strings are only used for colours".into()),
            )),
            _ => Err(self.err(
                t.span,
                format!("expected a value, found {}", describe(&t.tok)),
                Some("a value is a number, a name defined by `let`, or a list [a, b, c]".into()),
            )),
        }
    }

    /// Counts `n` more numbers and lists built against [`MAX_SCENE_WORK`], before they
    /// are built.
    fn charge(&mut self, n: usize, span: Span) -> Result<(), SceneError> {
        self.work = self.work.saturating_add(n);
        if self.work > MAX_SCENE_WORK {
            return Err(self.err(
                span,
                format!(
                    "the scene's evaluation exceeds its work budget of {MAX_SCENE_WORK} elements built"
                ),
                Some("the scene repeats arithmetic on large lists; simplify it".into()),
            ));
        }
        Ok(())
    }

    /// A list of `items`, within the budgets on nesting and on elements per value.
    fn make_list(&self, items: Vec<Value>, span: Span) -> Result<Value, SceneError> {
        let depth = 1 + items.iter().map(Value::depth).max().unwrap_or(0);
        if depth > MAX_NESTING {
            return Err(self.err(
                span,
                format!("nesting deeper than {MAX_NESTING} (lists inside lists, through `let` names too)"),
                Some("flatten the lists".into()),
            ));
        }
        let elements = items
            .iter()
            .fold(1usize, |n, v| n.saturating_add(v.elements()));
        if elements > MAX_VALUE_ELEMENTS {
            return Err(self.err(
                span,
                format!(
                    "this value holds more than {MAX_VALUE_ELEMENTS} elements (the budget per value), counting each use of a `let` name"
                ),
                Some("a list of lists repeated at every level grows exponentially; flatten it".into()),
            ));
        }
        Ok(Value::List(Rc::new(List {
            items,
            elements,
            depth,
        })))
    }

    fn arith(&mut self, op: Token, a: Value, b: Value) -> Result<Value, SceneError> {
        let Tok::Punct(c) = op.tok else {
            unreachable!("arith is called with an operator")
        };
        if c == '/' && matches!(b, Value::Num(y) if y == 0.0) {
            return Err(self.err(op.span, "division by zero", None));
        }
        // The result is as large as the larger operand: charge it before building.
        self.charge(a.elements().max(b.elements()), op.span)?;
        self.combine(c, op.span, &a, &b)
    }

    /// `a c b` elementwise; the depth of the recursion is that of the values, which
    /// [`Parser::make_list`] bounds by [`MAX_NESTING`].
    fn combine(&self, c: char, span: Span, a: &Value, b: &Value) -> Result<Value, SceneError> {
        let f = |x: f64, y: f64| match c {
            '+' => x + y,
            '-' => x - y,
            '*' => x * y,
            _ => x / y,
        };
        let items: Result<Vec<Value>, SceneError> = match (a, b) {
            (Value::Num(x), Value::Num(y)) => return Ok(Value::Num(f(*x, *y))),
            (Value::List(xs), Value::List(ys)) if "+-".contains(c) && xs.len() == ys.len() => xs
                .iter()
                .zip(ys.iter())
                .map(|(x, y)| self.combine(c, span, x, y))
                .collect(),
            (Value::List(xs), Value::Num(_)) if "*/".contains(c) => {
                xs.iter().map(|x| self.combine(c, span, x, b)).collect()
            }
            (Value::Num(_), Value::List(ys)) if c == '*' => {
                ys.iter().map(|y| self.combine(c, span, a, y)).collect()
            }
            _ => Err(self.err(
                span,
                format!("`{c}` cannot combine these values"),
                Some(
                    "lists of equal length add and subtract; a list multiplies or divides by a number"
                        .into(),
                ),
            )),
        };
        self.make_list(items?, span)
    }

    // ------------------------------------------------------------ the space

    fn finish(&self, s: Settings, objects: Vec<(Solid, Span)>) -> Result<Scene, SceneError> {
        let top = Span {
            line: 1,
            col: 1,
            width: 1,
        };
        let Some(first) = objects.first().map(|o| o.1) else {
            return Err(self.err(
                self.peek().span,
                "the scene has no solid",
                Some("add one, e.g. `sphere(r = 10)`".into()),
            ));
        };
        let n = objects.len();
        let solid = Solid::Union(
            objects
                .into_iter()
                .enumerate()
                .map(|(i, (o, _))| match o {
                    Solid::Coloured(..) => o,
                    o => o.colour(Colour::PALETTE[i % Colour::PALETTE.len()]),
                })
                .collect(),
        );
        let (lo, hi) = match s.bounds {
            Some((lo, hi, _)) => (lo, hi),
            None => {
                let csg = solid
                    .compile()
                    .map_err(|e| self.err(first, e.to_string(), None))?;
                match csg.bbox() {
                    Some((lo, hi)) if (0..3).all(|a| hi[a] > lo[a]) => (lo, hi),
                    Some(_) => {
                        return Err(self.err(
                            first,
                            "the scene's solids have an empty bounding box",
                            Some("add `bounds [xmin, ymin, zmin] [xmax, ymax, zmax]`".into()),
                        ))
                    }
                    None => {
                        return Err(self.err(
                            first,
                            "the scene is unbounded (a half-space or `not`), so its space cannot be inferred",
                            Some("add `bounds [xmin, ymin, zmin] [xmax, ymax, zmax]`".into()),
                        ))
                    }
                }
            }
        };
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0f64, f64::max);
        let (depth, voxel) = match (s.depth, s.voxel) {
            (Some((_, ds)), Some(_)) => return Err(self.err(
                ds,
                "both `depth` and `voxel` are set",
                Some(
                    "keep one: `depth` fits the voxel size to the bounds, `voxel` fits the depth"
                        .into(),
                ),
            )),
            (Some((d, _)), None) => (d, extent / f64::from(1u32 << d)),
            (None, Some((v, vs))) => {
                let cells = (extent / v).max(1.0);
                let d = cells.log2().ceil();
                if d > f64::from(MAX_SCENE_DEPTH) {
                    return Err(self.err(
                        vs,
                        format!(
                            "voxels this small need depth {d}, more than the limit {MAX_SCENE_DEPTH}"
                        ),
                        Some("use a larger voxel size or smaller bounds".into()),
                    ));
                }
                (d as u8, v)
            }
            (None, None) => {
                return Err(self.err(
                    top,
                    "the scene sets neither `depth` nor `voxel`",
                    Some("add a line such as `depth 8` at the top".into()),
                ))
            }
        };
        Ok(Scene {
            solid,
            depth,
            voxel,
            bounds_min: lo,
            objects: n,
            path: self.path.to_owned(),
        })
    }
}

fn statement_words() -> Vec<&'static str> {
    SHAPES
        .iter()
        .chain(GROUPS)
        .chain(SETTINGS)
        .chain(&["let"])
        .copied()
        .collect()
}

fn is_reserved(w: &str) -> bool {
    statement_words().contains(&w) || MODIFIERS.contains(&w) || w == "pi"
}

/// The parameter names each shape takes.
fn params_of(shape: &str) -> &'static [&'static str] {
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

fn example_of(shape: &str) -> &'static str {
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
