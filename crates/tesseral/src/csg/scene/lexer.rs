//! Tokens: the scene text cut into names, numbers, strings and punctuation, each
//! with its place in the file.

use super::parser::Parser;
use super::SceneError;

#[derive(Debug, Clone, PartialEq)]
pub(super) enum Tok {
    Ident(String),
    Num(f64),
    Str(String),
    Punct(char),
    Eof,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Span {
    pub(super) line: usize,
    pub(super) col: usize,
    pub(super) width: usize,
}

#[derive(Debug, Clone)]
pub(super) struct Token {
    pub(super) tok: Tok,
    pub(super) span: Span,
}

pub(super) fn describe(t: &Tok) -> String {
    match t {
        Tok::Ident(s) => format!("`{s}`"),
        Tok::Num(n) => format!("the number {n}"),
        Tok::Str(s) => format!("the string \"{s}\""),
        Tok::Punct(c) => format!("`{c}`"),
        Tok::Eof => "the end of the file".into(),
    }
}

impl Parser<'_> {
    pub(super) fn tokenize(&mut self, text: &str) -> Result<(), SceneError> {
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

    pub(super) fn peek(&self) -> &Token {
        &self.toks[self.pos]
    }

    pub(super) fn next(&mut self) -> Token {
        let t = self.toks[self.pos].clone();
        if self.pos + 1 < self.toks.len() {
            self.pos += 1;
        }
        t
    }

    pub(super) fn is_punct(&self, c: char) -> bool {
        self.peek().tok == Tok::Punct(c)
    }

    pub(super) fn expect(&mut self, c: char, hint: &str) -> Result<Token, SceneError> {
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
}
