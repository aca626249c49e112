//! Primitive calls: a shape's named parameters checked and turned into a [`Shape`].

use super::lexer::{describe, Span, Tok};
use super::parser::Parser;
use super::value::Value;
use super::words::{closest, example_of, params_of};
use super::{SceneError, MAX_PRIMITIVES};
use crate::csg::{Shape, Solid};

impl Parser<'_> {
    pub(super) fn primitive(&mut self, word: &str, span: Span) -> Result<Solid, SceneError> {
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

    pub(super) fn make_shape(
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
}
