//! `tesseral calc`: tesseral codes on the command line.
//!
//! Codes are octal digit strings, most significant digit first. Without `--digits` the
//! space is the signed 42-digit "tesseral hypercube": negative coordinates are two's
//! complement per axis, written with their repeating digit after `...` (`...6062` is
//! `…666062`, the code of (0, -5, -6)). With `--digits N` the space is bounded: codes
//! have exactly N digits and a carry out of the top digit is dropped and reported on
//! stderr, as Ahuja & Nash do.

use std::fmt::Write as _;

use anyhow::{bail, Context, Result};
use tesseral::code::digits::{add_by_table_traced, DigitSum};
use tesseral::code::notation::{format_padded, format_padic, parse_octal, parse_padic};
use tesseral::code::padic::padic_sub;
use tesseral::code::{Axis, Space, MAX_DEPTH_U128};

/// Arguments of `tesseral calc`.
#[derive(clap::Args)]
pub struct Args {
    /// Bounded space of N octal digits (1 to 42). A carry out of the top digit is
    /// dropped and reported on stderr. Without it: the signed 42-digit hypercube.
    #[arg(long, global = true, value_name = "N", allow_hyphen_values = true)]
    digits: Option<String>,
    /// Show the digit-by-digit work with carries, as the papers lay it out.
    #[arg(long, global = true)]
    explain: bool,
    /// Print JSON: `result` (the code, or `x y z` for decode), `coordinates` (decode
    /// and encode), `carry` (the digit lost out of a bounded space, 0 if none),
    /// `digits` (N, or null for the hypercube), `explanation` (lines, with --explain).
    #[arg(long, global = true)]
    json: bool,
    #[command(subcommand)]
    op: Op,
}

#[derive(clap::Subcommand)]
enum Op {
    /// Tesseral addition A + B: A translated by the vector from 0 to B.
    Add {
        /// Octal code, e.g. 642 (or ...6062, a code with negative coordinates).
        #[arg(allow_hyphen_values = true)]
        a: String,
        /// Octal code, e.g. 642 (or ...6062, a code with negative coordinates).
        #[arg(allow_hyphen_values = true)]
        b: String,
    },
    /// Tesseral subtraction A - B, by the P-adic method.
    Sub {
        /// Octal code, e.g. 642 (or ...6062, a code with negative coordinates).
        #[arg(allow_hyphen_values = true)]
        a: String,
        /// Octal code, e.g. 642 (or ...6062, a code with negative coordinates).
        #[arg(allow_hyphen_values = true)]
        b: String,
    },
    /// Negation: the two's complement of every axis.
    Neg {
        /// Octal code, e.g. 642 (or ...6062, a code with negative coordinates).
        #[arg(allow_hyphen_values = true)]
        a: String,
    },
    /// Prints the octal tesseral code of X Y Z (negative coordinates allowed).
    Encode {
        /// x coordinate (east).
        #[arg(allow_hyphen_values = true)]
        x: String,
        /// y coordinate (north).
        #[arg(allow_hyphen_values = true)]
        y: String,
        /// z coordinate (up).
        #[arg(allow_hyphen_values = true)]
        z: String,
    },
    /// Prints the coordinates `X Y Z` of an octal code.
    Decode {
        /// Octal code, e.g. 642 (or ...6062, a code with negative coordinates).
        #[arg(allow_hyphen_values = true)]
        code: String,
    },
}

/// The space codes live in, checked once before any work.
struct Mode {
    space: Space<u128>,
    /// `--digits N` given: unsigned codes of exactly N digits, carries dropped.
    bounded: bool,
}

impl Mode {
    fn from_flag(digits: Option<&str>) -> Result<Mode> {
        let Some(text) = digits else {
            return Ok(Mode {
                space: Space::full(),
                bounded: false,
            });
        };
        let n: u32 = text
            .trim()
            .parse()
            .ok()
            .filter(|n| (1..=MAX_DEPTH_U128).contains(n))
            .with_context(|| {
                format!("argument --digits `{text}`: expected a whole number from 1 to {MAX_DEPTH_U128}")
            })?;
        Ok(Mode {
            space: Space::new(n)?,
            bounded: true,
        })
    }

    fn depth(&self) -> u32 {
        self.space.depth()
    }

    fn parse(&self, name: &str, text: &str) -> Result<u128> {
        let r = if self.bounded {
            parse_octal(text, self.depth())
        } else {
            parse_padic(text, &self.space)
        };
        r.with_context(|| format!("argument {name} `{text}`"))
    }

    fn show(&self, code: u128) -> String {
        if self.bounded {
            format_padded(code, self.depth())
        } else {
            format_padic(code, &self.space)
        }
    }

    /// A code inside an explanation: its digits without padding.
    fn show_short(&self, code: u128) -> String {
        if self.bounded {
            format!("{code:o}")
        } else {
            format_padic(code, &self.space)
        }
    }

    fn parse_coord(&self, name: &str, text: &str) -> Result<i64> {
        let v: i64 = text
            .trim()
            .parse()
            .ok()
            .with_context(|| format!("argument {name} `{text}`: not an integer"))?;
        let d = self.depth();
        let ok = if self.bounded {
            // Ahuja & Nash write -5 in three binary digits as 011: allow |v| < 2^N.
            v.unsigned_abs() < 1u64 << d
        } else {
            (-(1i64 << (d - 1))..(1i64 << (d - 1))).contains(&v)
        };
        if !ok {
            if self.bounded {
                bail!("argument {name} `{text}`: outside the {d}-digit space (|{name}| < 2^{d})");
            }
            bail!(
                "argument {name} `{text}`: outside the {d}-digit hypercube (-2^{h} <= {name} < 2^{h})",
                h = d - 1
            );
        }
        Ok(v)
    }
}

fn axes_of(carry: u8) -> String {
    Axis::ALL
        .iter()
        .filter(|a| carry & a.unit_digit() != 0)
        .map(|a| a.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Runs `tesseral calc`.
pub fn run(args: Args) -> Result<()> {
    let mode = Mode::from_flag(args.digits.as_deref())?;
    let s = mode.space;
    let mut out = String::new();
    match &args.op {
        Op::Add { a, b } => {
            let (ca, cb) = (mode.parse("A", a)?, mode.parse("B", b)?);
            let r = s.overflowing_add(ca, cb);
            if mode.bounded {
                if args.explain {
                    explain_add(&mode, ca, cb, &mut out);
                }
                writeln!(out, "{}", mode.show(r.code))?;
                return finish(&args, &mode, &out, None, ("carry", r.carry));
            }
            let sum = s
                .checked_add_signed(ca, cb)
                .context("result out of range: a coordinate leaves the 42-digit hypercube")?;
            if args.explain {
                explain_add(&mode, ca, cb, &mut out);
            }
            writeln!(out, "{}", mode.show(sum))?;
        }
        Op::Sub { a, b } => {
            let (ca, cb) = (mode.parse("A", a)?, mode.parse("B", b)?);
            let r = s.overflowing_sub(ca, cb);
            let code = if mode.bounded {
                r.code
            } else {
                s.checked_sub_signed(ca, cb)
                    .context("result out of range: a coordinate leaves the 42-digit hypercube")?
            };
            if args.explain {
                explain_sub(&mode, ca, cb, &mut out)?;
            }
            writeln!(out, "{}", mode.show(code))?;
            let carry = if mode.bounded { r.carry } else { 0 };
            return finish(&args, &mode, &out, None, ("borrow", carry));
        }
        Op::Neg { a } => {
            let ca = mode.parse("A", a)?;
            let code = if mode.bounded {
                s.neg(ca)
            } else {
                s.checked_neg_signed(ca)
                    .context("result out of range: a coordinate leaves the 42-digit hypercube")?
            };
            if args.explain {
                let comp = !ca & s.mask();
                writeln!(
                    out,
                    "negation: two's complement on each axis: complement every digit (7 - d), then add 7 (one unit along x, y and z)"
                )?;
                writeln!(
                    out,
                    "complement of {} is {}",
                    mode.show(ca),
                    mode.show(comp)
                )?;
                explain_add(&mode, comp, 7, &mut out);
            }
            writeln!(out, "{}", mode.show(code))?;
        }
        Op::Encode { x, y, z } => {
            let p = [
                mode.parse_coord("X", x)?,
                mode.parse_coord("Y", y)?,
                mode.parse_coord("Z", z)?,
            ];
            let code = s.encode_wrapping(p);
            if args.explain {
                explain_bits(&mode, code, &mut out, true);
            }
            writeln!(out, "{}", mode.show(code))?;
            return finish(&args, &mode, &out, Some(p), ("carry", 0));
        }
        Op::Decode { code } => {
            let c = mode.parse("CODE", code)?;
            if args.explain {
                explain_bits(&mode, c, &mut out, false);
            }
            let p = if mode.bounded {
                s.decode_unsigned(c).map(|v| v as i64)
            } else {
                s.decode_signed(c)
            };
            writeln!(out, "{} {} {}", p[0], p[1], p[2])?;
            return finish(&args, &mode, &out, Some(p), ("carry", 0));
        }
    }
    finish(&args, &mode, &out, None, ("carry", 0))
}

/// Prints the work and result (text, or JSON with --json), and notes on stderr a
/// carry (or borrow) lost out of a bounded space.
fn finish(
    args: &Args,
    mode: &Mode,
    out: &str,
    coordinates: Option<[i64; 3]>,
    (kind, carry): (&str, u8),
) -> Result<()> {
    let text = tidy(out);
    if args.json {
        let mut lines: Vec<&str> = text.lines().collect();
        let result = lines.pop().unwrap_or_default();
        let mut v = serde_json::json!({
            "result": result,
            "carry": carry,
            "digits": mode.bounded.then(|| mode.depth()),
        });
        if let Some(p) = coordinates {
            v["coordinates"] = serde_json::json!(p);
        }
        if args.explain {
            v["explanation"] = serde_json::json!(lines);
        }
        crate::outln!("{v}")?;
    } else {
        crate::out!("{text}")?;
    }
    if carry != 0 {
        eprintln!(
            "note: {kind} {carry} lost out of the top digit (along {}); the result wrapped around the {}-digit space",
            axes_of(carry),
            mode.depth()
        );
    }
    Ok(())
}

/// The output with trailing spaces removed from every line.
fn tidy(out: &str) -> String {
    out.lines().map(|l| format!("{}\n", l.trim_end())).collect()
}

/// Number of digits worth showing: all of a bounded space; in the hypercube, up to
/// the highest digit that differs from the repeating sign digit, plus one.
fn shown_digits(mode: &Mode, codes: &[u128]) -> u32 {
    if mode.bounded {
        return mode.depth();
    }
    let s = &mode.space;
    codes
        .iter()
        .map(|&c| {
            let r = s.sign_digit(c);
            (0..s.depth())
                .rev()
                .find(|&i| ((c >> (3 * i)) & 7) as u8 != r)
                .map_or(1, |i| i + 2)
        })
        .max()
        .unwrap_or(1)
        .min(s.depth())
}

fn row(label: &str, digits: &[String], width: usize) -> String {
    let body: String = digits.iter().map(|d| format!("{d:>2}")).collect();
    format!("{label:>9} {body:>width$}")
}

/// The column addition of Harakal & Chmúrny §3 with Table 1, carries on top.
fn explain_add(mode: &Mode, a: u128, b: u128, out: &mut String) {
    let DigitSum { columns, carry, .. } = add_by_table_traced(a, b, mode.depth());
    let mut n = shown_digits(mode, &[a, b]) as usize;
    // In the hypercube keep going while carries still ripple.
    if !mode.bounded {
        while n < columns.len() && columns[n].carry_in != columns[n].carry_out {
            n += 1;
        }
        n = (n + 1).min(columns.len());
    }
    let cols = &columns[..n];
    let digits_of = |f: &dyn Fn(&tesseral::code::digits::AddColumn) -> u8| -> Vec<String> {
        cols.iter().rev().map(|c| f(c).to_string()).collect()
    };
    let _ = writeln!(
        out,
        "tesseral addition, digit by digit with Harakal & Chmúrny Table 1 (least significant digit first):"
    );
    // Each carry sits above the column it goes into, as in school arithmetic; a carry
    // out of the top of a bounded space sits above the margin.
    let mut carries: Vec<String> = vec![if mode.bounded && carry != 0 {
        carry.to_string()
    } else {
        " ".into()
    }];
    carries.extend(cols.iter().rev().map(|c| {
        if c.carry_in == 0 {
            " ".into()
        } else {
            c.carry_in.to_string()
        }
    }));
    let width = 2 * (n + 1);
    let lead = if mode.bounded { " " } else { "…" };
    let mut a_digits = vec![lead.to_owned()];
    a_digits.extend(digits_of(&|c| c.a));
    let mut b_digits = vec![lead.to_owned()];
    b_digits.extend(digits_of(&|c| c.b));
    let mut r_digits = vec![lead.to_owned()];
    r_digits.extend(digits_of(&|c| c.digit));
    let _ = writeln!(out, "{}", row("carries", &carries, width).trim_end());
    let _ = writeln!(out, "{}", row("", &a_digits, width));
    let _ = writeln!(out, "{}", row("+", &b_digits, width));
    let _ = writeln!(out, "{:>9} {}", "", "-".repeat(width));
    let _ = writeln!(out, "{}", row("", &r_digits, width));
    for c in cols {
        let _ = write!(
            out,
            "digit {}: {} + {} = {}{}",
            c.position, c.a, c.b, c.first.0, c.first.1
        );
        if c.carry_in != 0 {
            let _ = write!(
                out,
                "; {} + carry {} = {}{}",
                c.first.1, c.carry_in, c.second.0, c.second.1
            );
        }
        let _ = write!(out, " -> digit {}", c.digit);
        if c.carry_out != 0 {
            let _ = write!(
                out,
                ", carry {} (along {})",
                c.carry_out,
                axes_of(c.carry_out)
            );
        }
        out.push('\n');
    }
    if mode.bounded {
        if carry != 0 {
            let _ = writeln!(
                out,
                "carry {carry} out of digit {} is lost (Ahuja & Nash: \"carry lost\")",
                mode.depth() - 1
            );
        }
    } else if n < columns.len() {
        let last = &columns[n - 1];
        let _ = writeln!(
            out,
            "higher digits repeat: {} + {} + carry {} -> digit {} forever",
            last.a, last.b, last.carry_in, last.digit
        );
    }
}

fn primes(k: usize) -> String {
    if k <= 3 {
        "'".repeat(k)
    } else {
        format!("({k})")
    }
}

/// The P-adic subtraction of Harakal & Chmúrny §3, one equation per line.
fn explain_sub(mode: &Mode, a: u128, b: u128, out: &mut String) -> Result<()> {
    let p = padic_sub(&mode.space, a, b, !mode.bounded);
    writeln!(
        out,
        "tesseral subtraction {} - {} by the P-adic method (Harakal & Chmúrny §3, Table 2):",
        mode.show_short(a),
        mode.show_short(b)
    )?;
    writeln!(
        out,
        "solve {} + T = {} from the right; Table 2 row = digit of T_a, column = digit of T_b, entry \"carry, digit\"",
        mode.show_short(b),
        mode.show_short(a)
    )?;
    let mut found = String::new();
    let tw = p.steps.len();
    for (k, st) in p.steps.iter().enumerate() {
        found.insert(0, char::from(b'0' + st.x));
        let eq = format!(
            "{} + T{} = {}",
            mode.show_short(st.ta),
            primes(k),
            mode.show_short(st.tb)
        );
        write!(
            out,
            "{eq:<28} Table 2 [{}][{}] = {},{}: digit {}, carry {}   T = ...{found:<tw$}",
            st.a, st.b, st.carry, st.x, st.x, st.carry
        )?;
        if k + 1 < p.steps.len() {
            writeln!(
                out,
                "   next T_a: {} + {} = {}",
                mode.show_short(mode.space.shr_digit(st.ta, !mode.bounded)),
                st.carry,
                mode.show_short(st.next_ta)
            )?;
        } else {
            out.push('\n');
        }
    }
    let rep: String = p
        .repeating_digits()
        .iter()
        .rev()
        .map(|&d| char::from(b'0' + d))
        .collect();
    writeln!(
        out,
        "the equation of step {} comes back: its digit{} {rep} repeat{} forever to the left",
        p.repeat_from + 1,
        if rep.len() > 1 { "s" } else { "" },
        if rep.len() > 1 { "" } else { "s" },
    )?;
    if mode.bounded && rep != "0" {
        writeln!(
            out,
            "the space keeps {} digits; the repeating digits beyond them are dropped",
            mode.depth()
        )?;
    }
    Ok(())
}

/// The bit interleave of Harakal & Chmúrny §3 (x in bit 0 of a digit, docs/conventions.md).
fn explain_bits(mode: &Mode, code: u128, out: &mut String, encoding: bool) {
    let n = if mode.bounded {
        mode.depth()
    } else {
        shown_digits(mode, &[code]).max(1)
    };
    let _ = writeln!(
        out,
        "{}: digit d = x + 2y + 4z, one bit of each coordinate per digit, most significant digit first",
        if encoding { "interleave" } else { "de-interleave" }
    );
    let bits = |axis: u32| -> String {
        (0..n)
            .rev()
            .map(|i| char::from(b'0' + ((code >> (3 * i + axis)) & 1) as u8))
            .collect()
    };
    let ext = if mode.bounded { "" } else { "..." };
    for axis in Axis::ALL {
        let _ = writeln!(out, "  {} bits: {ext}{}", axis.name(), bits(axis.shift()));
    }
    for i in (0..n).rev() {
        let d = ((code >> (3 * i)) & 7) as u8;
        let note = if !mode.bounded && i == n - 1 && i + 1 < mode.depth() {
            " (repeats to the left)"
        } else {
            ""
        };
        let _ = writeln!(
            out,
            "  digit {i}: z {} y {} x {} -> {d}{note}",
            (d >> 2) & 1,
            (d >> 1) & 1,
            d & 1
        );
    }
}
