//! The parser's state and the statements: settings, `let`, solids with their
//! modifiers, colours and groups.

use std::collections::HashMap;
use std::path::Path;

use super::lexer::{describe, Span, Tok, Token};
use super::value::Value;
use super::words::{closest, is_reserved, statement_words};
use super::{
    Diagnostic, Scene, SceneError, GROUPS, MAX_NESTING, MAX_SCENE_BYTES, MAX_SCENE_DEPTH,
    MODIFIERS, SETTINGS, SHAPES,
};
use crate::csg::{Colour, Solid};

pub(super) struct Parser<'a> {
    pub(super) path: &'a Path,
    pub(super) lines: Vec<&'a str>,
    pub(super) toks: Vec<Token>,
    pub(super) pos: usize,
    pub(super) lets: HashMap<String, (Value, usize)>,
    pub(super) prims: usize,
    pub(super) nesting: usize,
    /// Numbers and lists built so far, against [`MAX_SCENE_WORK`](super::MAX_SCENE_WORK).
    pub(super) work: usize,
}

pub(super) struct Settings {
    pub(super) depth: Option<(u8, Span)>,
    pub(super) voxel: Option<(f64, Span)>,
    pub(super) bounds: Option<([f64; 3], [f64; 3], Span)>,
}

impl<'a> Parser<'a> {
    pub(super) fn new(text: &'a str, path: &'a Path) -> Result<Self, SceneError> {
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

    pub(super) fn err(
        &self,
        span: Span,
        message: impl Into<String>,
        hint: Option<String>,
    ) -> SceneError {
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

    pub(super) fn enter(&mut self, span: Span) -> Result<(), SceneError> {
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

    pub(super) fn file(&mut self) -> Result<Scene, SceneError> {
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

    pub(super) fn once(
        &self,
        prev: Option<Span>,
        span: Span,
        what: &str,
    ) -> Result<(), SceneError> {
        match prev {
            Some(p) => Err(self.err(
                span,
                format!("`{what}` is set twice"),
                Some(format!("it was first set on line {}; keep one", p.line)),
            )),
            None => Ok(()),
        }
    }

    pub(super) fn let_statement(&mut self) -> Result<(), SceneError> {
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

    pub(super) fn solid(&mut self) -> Result<Solid, SceneError> {
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

    pub(super) fn modifiers(&mut self, base: Solid) -> Result<Solid, SceneError> {
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

    pub(super) fn colour(&mut self) -> Result<Colour, SceneError> {
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

    pub(super) fn group(&mut self, word: &str, span: Span) -> Result<Solid, SceneError> {
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
}
