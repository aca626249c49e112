//! `calc mul`, `calc div` and `calc qmul`: tesseral multiplication and division and
//! the integer-quaternion rotation, with their `--explain` work.

use std::fmt::Write as _;

use anyhow::{bail, Context, Result};
use tesseral::code::muldiv::{padic_div, quaternion_apply, Division};
use tesseral::code::notation::format_padded;
use tesseral::code::Axis;

use super::{axes_of, Mode};

/// The most steps a division takes looking for the repeating digits.
const MAX_DIVISION_STEPS: usize = 4096;
/// The longest repeating block written out in a quotient.
const MAX_SHOWN_PERIOD: usize = 64;

fn digits_msd_first(digits: &[u8]) -> String {
    digits.iter().rev().map(|&d| char::from(b'0' + d)).collect()
}

/// `a * b`: the product and the lost carry (bounded spaces only).
pub(super) fn mul(mode: &Mode, a: u128, b: u128, explain: bool, out: &mut String) -> Result<u8> {
    let s = &mode.space;
    let r = s.overflowing_mul(a, b);
    let code = if mode.bounded {
        r.code
    } else {
        s.checked_mul_signed(a, b)
            .context("result out of range: a coordinate leaves the 42-digit hypercube")?
    };
    if explain {
        writeln!(
            out,
            "tesseral multiplication {} * {}: coordinates multiplied axis by axis, by shift and add on the codes",
            mode.show_short(a),
            mode.show_short(b)
        )?;
        writeln!(
            out,
            "for each digit d of {} (least significant first), the axes set in d get {} shifted that many digits, added with Table 1:",
            mode.show_short(b),
            mode.show_short(a)
        )?;
        let mut acc = 0u128;
        for i in 0..s.depth() {
            let d = ((b >> (3 * i)) & 7) as u8;
            if d == 0 {
                continue;
            }
            let term = ((a & s.axes_mask(d)) << (3 * i)) & s.mask();
            acc = s.add(acc, term);
            writeln!(
                out,
                "digit {} = {d} (along {}): + {} = {}",
                i + 1,
                axes_of(d),
                mode.show_short(term),
                mode.show_short(acc)
            )?;
        }
    }
    writeln!(out, "{}", mode.show(code))?;
    Ok(if mode.bounded { r.carry } else { 0 })
}

/// The quotient as the hypercube writes it: a repeating sign digit as `...d`, a
/// longer repeating block in brackets (`...[01]1` is 1/3 along x).
fn show_quotient(mode: &Mode, q: &Division<u128>) -> String {
    if mode.bounded {
        return format_padded(q.result, mode.depth());
    }
    match q.repeating_digits(MAX_SHOWN_PERIOD) {
        Some(rep) if rep.len() == 1 => mode.show(q.result),
        Some(rep) => format!(
            "...[{}]{}",
            digits_msd_first(&rep),
            digits_msd_first(&q.leading_digits())
        ),
        None => format!("...{}", format_padded(q.result, mode.depth())),
    }
}

/// `b / a` by the P-adic method.
pub(super) fn div(mode: &Mode, b: u128, a: u128, explain: bool, out: &mut String) -> Result<()> {
    let s = &mode.space;
    let q = padic_div(s, b, a, !mode.bounded, MAX_DIVISION_STEPS)
        .with_context(|| format!("{} / {}", mode.show_short(b), mode.show_short(a)))?;
    if explain {
        writeln!(
            out,
            "tesseral division {} / {} by the P-adic method: solve {} * T = {} digit by digit from the right",
            mode.show_short(b),
            mode.show_short(a),
            mode.show_short(a),
            mode.show_short(b)
        )?;
        for &(axis, ta, tb) in &q.halvings {
            writeln!(
                out,
                "the divisor is even along {}: halve both: {} * T = {}",
                axes_of(axis),
                mode.show_short(ta),
                mode.show_short(tb)
            )?;
        }
        let up = s.shr_digit(q.divisor, !mode.bounded);
        let mut found = Vec::new();
        for (k, st) in q.steps.iter().enumerate() {
            found.push(st.x);
            let axes = if st.x == 0 {
                "none".to_owned()
            } else {
                axes_of(st.x)
            };
            writeln!(
                out,
                "step {:>3}: left {:<14} odd along {axes:<8} digit {}; take {} along them and move down: {}   T = ...{}",
                k + 1,
                mode.show_short(st.tb),
                st.x,
                mode.show_short(up),
                mode.show_short(st.next),
                digits_msd_first(&found)
            )?;
        }
        for (k, axis) in Axis::ALL.iter().enumerate() {
            match q.cycles[k] {
                Some((start, period)) => writeln!(
                    out,
                    "along {}: the remainder of step {} comes back after {period} step{}: from digit {} the bits repeat",
                    axis.name(),
                    start + 1,
                    if period == 1 { "" } else { "s" },
                    start + 1
                )?,
                None => writeln!(
                    out,
                    "along {}: no remainder came back within {MAX_DIVISION_STEPS} steps",
                    axis.name()
                )?,
            }
        }
        match q.cycle() {
            Some((start, period)) => writeln!(
                out,
                "so the digits repeat from digit {} with period {period}",
                start + 1
            )?,
            None => writeln!(out, "the period of the whole code is not known")?,
        }
    }
    writeln!(out, "{}", show_quotient(mode, &q))?;
    Ok(())
}

/// Parses `a,b,c,d`: four integers, each below 2^20 in size.
fn parse_quaternion(text: &str) -> Result<[i64; 4]> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != 4 {
        bail!("argument Q `{text}`: expected four integers a,b,c,d");
    }
    let mut q = [0i64; 4];
    for (i, p) in parts.iter().enumerate() {
        q[i] = p
            .parse::<i64>()
            .ok()
            .filter(|v| v.unsigned_abs() < 1 << 20)
            .with_context(|| {
                format!("argument Q `{text}`: `{p}` is not an integer below 2^20 in size")
            })?;
    }
    if q == [0; 4] {
        bail!("argument Q `{text}`: the zero quaternion maps everything to the origin");
    }
    Ok(q)
}

/// `q v q̄` on the coordinates of `code`.
pub(super) fn qmul(
    mode: &Mode,
    code: u128,
    q_text: &str,
    explain: bool,
    out: &mut String,
) -> Result<[i64; 3]> {
    let q = parse_quaternion(q_text)?;
    let s = &mode.space;
    let v = if mode.bounded {
        s.decode_unsigned(code).map(|c| c as i64)
    } else {
        s.decode_signed(code)
    };
    let r = quaternion_apply(q, v);
    let p: [i64; 3] = r.map(|c| i64::try_from(c).unwrap_or(i64::MAX));
    let code = if mode.bounded {
        s.encode_unsigned(p.map(|c| u64::try_from(c).unwrap_or(u64::MAX)))
            .with_context(|| {
                format!(
                    "result ({}, {}, {}) out of range: outside the {}-digit space",
                    r[0],
                    r[1],
                    r[2],
                    mode.depth()
                )
            })?
    } else {
        s.encode_signed(p).with_context(|| {
            format!(
                "result ({}, {}, {}) out of range: a coordinate leaves the 42-digit hypercube",
                r[0], r[1], r[2]
            )
        })?
    };
    if explain {
        let n: i64 = q.iter().map(|c| c * c).sum();
        let u = [q[1], q[2], q[3]].map(|c| c as f64);
        let len = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
        let angle = 2.0 * len.atan2(q[0] as f64);
        writeln!(
            out,
            "q = {} + {}i + {}j + {}k: a rotation by {:.4}° about ({}, {}, {}), scaled by |q|² = {n}",
            q[0],
            q[1],
            q[2],
            q[3],
            angle.to_degrees(),
            q[1],
            q[2],
            q[3]
        )?;
        writeln!(
            out,
            "q v q̄ = (a² - |u|²) v + 2 (u·v) u + 2a (u × v): ({}, {}, {}) -> ({}, {}, {})",
            v[0], v[1], v[2], p[0], p[1], p[2]
        )?;
    }
    writeln!(out, "{}", mode.show(code))?;
    Ok(p)
}
