//! Values and expressions: numbers and shared lists, `let` names, arithmetic, and
//! the budgets on what a value holds and what the whole scene may compute.

use std::rc::Rc;

use super::lexer::{describe, Span, Tok, Token};
use super::parser::Parser;
use super::words::closest;
use super::{SceneError, MAX_NESTING, MAX_SCENE_WORK, MAX_VALUE_ELEMENTS};

/// A value of the scene language. Lists are shared, not copied: a `let` name used
/// twice costs one pointer, which is what keeps `let b = [a, a, a]` cheap; what a
/// value *would* cost if expanded is kept in `List::elements` and budgeted.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Value {
    Num(f64),
    List(Rc<List>),
}

#[derive(Debug, PartialEq)]
pub(super) struct List {
    pub(super) items: Vec<Value>,
    /// The numbers and lists this list holds, itself included, counted through
    /// sharing.
    pub(super) elements: usize,
    /// Lists inside lists: `[1]` has depth 1.
    pub(super) depth: usize,
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

impl Parser<'_> {
    pub(super) fn num(&self, v: &Value, span: Span, what: &str) -> Result<f64, SceneError> {
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

    pub(super) fn list(
        &self,
        v: &Value,
        span: Span,
        what: &str,
        n: usize,
    ) -> Result<Vec<f64>, SceneError> {
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

    pub(super) fn vec3(&self, v: &Value, span: Span, what: &str) -> Result<[f64; 3], SceneError> {
        let l = self.list(v, span, what, 3)?;
        Ok([l[0], l[1], l[2]])
    }

    pub(super) fn expr_span(&mut self) -> Result<(Value, Span), SceneError> {
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

    pub(super) fn expr(&mut self) -> Result<Value, SceneError> {
        let mut v = self.term()?;
        while self.is_punct('+') || self.is_punct('-') {
            let op = self.next();
            let r = self.term()?;
            v = self.arith(op, v, r)?;
        }
        Ok(v)
    }

    pub(super) fn term(&mut self) -> Result<Value, SceneError> {
        let mut v = self.unary()?;
        while self.is_punct('*') || self.is_punct('/') {
            let op = self.next();
            let r = self.unary()?;
            v = self.arith(op, v, r)?;
        }
        Ok(v)
    }

    /// Unary minus, iteratively: a run of signs is any length without using the stack.
    pub(super) fn unary(&mut self) -> Result<Value, SceneError> {
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

    pub(super) fn atom(&mut self) -> Result<Value, SceneError> {
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
    pub(super) fn charge(&mut self, n: usize, span: Span) -> Result<(), SceneError> {
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
    pub(super) fn make_list(&self, items: Vec<Value>, span: Span) -> Result<Value, SceneError> {
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

    pub(super) fn arith(&mut self, op: Token, a: Value, b: Value) -> Result<Value, SceneError> {
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
    pub(super) fn combine(
        &self,
        c: char,
        span: Span,
        a: &Value,
        b: &Value,
    ) -> Result<Value, SceneError> {
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
}
