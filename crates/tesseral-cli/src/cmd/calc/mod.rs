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
use tesseral::code::notation::{format_padded, format_padic, parse_octal, parse_padic};
use tesseral::code::{Axis, Space, MAX_DEPTH_U128};

mod explain;
mod muldiv;
use explain::{explain_add, explain_bits, explain_sub};

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
    /// Tesseral multiplication A * B: coordinates multiplied axis by axis (7 is the
    /// unit; 70 doubles; a negative coordinate mirrors), by shift and add on the codes.
    Mul {
        /// Octal code, e.g. 642 (or ...6062, a code with negative coordinates).
        #[arg(allow_hyphen_values = true)]
        a: String,
        /// Octal code, e.g. 70 (or ...6062, a code with negative coordinates).
        #[arg(allow_hyphen_values = true)]
        b: String,
    },
    /// Tesseral division B / A by the P-adic method: exact on each axis whose divisor
    /// is odd, a 2-adic number with repeating digits when not an integer (such as
    /// ...\[01\]1, 1/3 along x).
    Div {
        /// The dividend: octal code, e.g. 6530.
        #[arg(allow_hyphen_values = true)]
        b: String,
        /// The divisor: octal code, e.g. 70.
        #[arg(allow_hyphen_values = true)]
        a: String,
    },
    /// Rotation with scaling by the integer quaternion q = a + bi + cj + dk: the
    /// coordinates of CODE become q v q̄ (rotated by 2·atan2(|(b,c,d)|, a) about
    /// (b, c, d), scaled by a² + b² + c² + d²).
    Qmul {
        /// Octal code, e.g. 642 (or ...6062, a code with negative coordinates).
        #[arg(allow_hyphen_values = true)]
        code: String,
        /// The quaternion a,b,c,d, such as 1,0,0,1 (a quarter turn about z, times 2).
        #[arg(allow_hyphen_values = true)]
        q: String,
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
        Op::Mul { a, b } => {
            let (ca, cb) = (mode.parse("A", a)?, mode.parse("B", b)?);
            let carry = muldiv::mul(&mode, ca, cb, args.explain, &mut out)?;
            return finish(&args, &mode, &out, None, ("carry", carry));
        }
        Op::Div { b, a } => {
            let (cb, ca) = (mode.parse("B", b)?, mode.parse("A", a)?);
            muldiv::div(&mode, cb, ca, args.explain, &mut out)?;
        }
        Op::Qmul { code, q } => {
            let c = mode.parse("CODE", code)?;
            let p = muldiv::qmul(&mode, c, q, args.explain, &mut out)?;
            return finish(&args, &mode, &out, Some(p), ("carry", 0));
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
