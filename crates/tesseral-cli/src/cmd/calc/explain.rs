//! `calc --explain`: the digit-by-digit work, laid out as the papers do.

use std::fmt::Write as _;

use anyhow::Result;
use tesseral::code::digits::{add_by_table_traced, DigitSum};
use tesseral::code::padic::padic_sub;
use tesseral::code::Axis;

use super::{axes_of, Mode};

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
pub(super) fn explain_add(mode: &Mode, a: u128, b: u128, out: &mut String) {
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
pub(super) fn explain_sub(mode: &Mode, a: u128, b: u128, out: &mut String) -> Result<()> {
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
pub(super) fn explain_bits(mode: &Mode, code: u128, out: &mut String, encoding: bool) {
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
