//! Every fast path held against a naive model, and the papers' worked examples.

use super::digits::{self, add_by_table, add_by_table_traced, ADD_TABLE, SUB_TABLE};
use super::notation::{format_padded, format_padic, parse_octal, parse_padic};
use super::padic::padic_sub;
use super::*;
use core::cmp::Ordering;
use proptest::prelude::*;

/// A tiny seeded generator (PCG-style LCG output mix), so failures name their seed.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let x = self.0;
        (x ^ (x >> 29)).wrapping_mul(0xbf58_476d_1ce4_e5b9) ^ (x >> 32)
    }
}

const SEED: u64 = 0x7e55_e4a1_2024_0001;

/// Bit-by-bit interleave: the obviously right reference.
fn naive_encode<W: CodeWord>(p: [u64; 3]) -> W {
    let mut c = W::ZERO;
    for i in 0..W::MAX_DEPTH {
        for (axis, &v) in p.iter().enumerate() {
            if (v >> i) & 1 == 1 {
                c = c | (W::from_digit(1) << (3 * i + axis as u32));
            }
        }
    }
    c
}

fn naive_decode<W: CodeWord>(c: W) -> [u64; 3] {
    let mut p = [0u64; 3];
    for i in 0..W::MAX_DEPTH {
        let d = (c >> (3 * i)).low_digit();
        for (axis, v) in p.iter_mut().enumerate() {
            *v |= u64::from((d >> axis) & 1) << i;
        }
    }
    p
}

fn random_point(rng: &mut Rng, depth: u32) -> [u64; 3] {
    let m = if depth >= 64 { !0 } else { (1u64 << depth) - 1 };
    [rng.next() & m, rng.next() & m, rng.next() & m]
}

fn check_addressing<W: CodeWord>(seed: u64) {
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    let n = 5000;
    let pts: Vec<[u64; 3]> = (0..n)
        .map(|_| random_point(&mut rng, W::MAX_DEPTH))
        .collect();
    let coords: Vec<[W::Coord; 3]> = pts.iter().map(|p| p.map(W::coord_from_u64)).collect();
    let mut out = vec![W::ZERO; n];
    let mut back = vec![[W::Coord::default(); 3]; n];
    for backend in [Backend::MagicBits, Backend::Bmi2] {
        if !backend.is_available() {
            println!("{backend:?} not available on this CPU: skipped");
            continue;
        }
        batch::encode_slice_with(backend, &coords, &mut out).unwrap();
        batch::decode_slice_with(backend, &out, &mut back).unwrap();
        for i in 0..n {
            let want: W = naive_encode(pts[i]);
            assert_eq!(
                out[i], want,
                "{backend:?} encode {:?} (seed {seed:#x})",
                pts[i]
            );
            assert_eq!(naive_decode(out[i]), pts[i]);
            assert_eq!(back[i].map(W::coord_to_u64), pts[i], "{backend:?} decode");
            let [x, y, z] = coords[i];
            assert_eq!(W::encode(x, y, z), want);
            assert_eq!(want.decode(), coords[i]);
            if backend == Backend::Bmi2 {
                // SAFETY: availability checked above.
                unsafe {
                    assert_eq!(W::encode_bmi2(x, y, z), want);
                    assert_eq!(want.decode_bmi2(), coords[i]);
                }
            }
        }
    }
}

#[test]
fn addressing_u64_matches_bit_by_bit_reference() {
    check_addressing::<u64>(SEED);
}

#[test]
fn addressing_u128_matches_bit_by_bit_reference() {
    check_addressing::<u128>(SEED ^ 0x55);
}

#[test]
fn addressing_edges() {
    let m21 = (1u32 << 21) - 1;
    assert_eq!(encode(m21, m21, m21), (1u64 << 63) - 1);
    assert_eq!(decode((1u64 << 63) - 1), [m21; 3]);
    // Bits above depth 21 are dropped, and bit 63 of a code is ignored.
    assert_eq!(encode(1 << 21, 0, 0), 0);
    assert_eq!(decode(1 << 63), [0, 0, 0]);
    let m42 = (1u64 << 42) - 1;
    assert_eq!(encode_wide(m42, m42, m42), (1u128 << 126) - 1);
    assert_eq!(decode_wide((1u128 << 126) - 1), [m42; 3]);
    assert_eq!(encode_wide(1 << 42, 0, 0), 0);
    assert_eq!(dilate3(m21), 0x1249_2492_4924_9249);
    assert_eq!(undilate3(!0), m21);
    assert_eq!(<u64 as CodeWord>::X_MASK, 0x1249_2492_4924_9249);
    assert_eq!(
        batch::encode_slice::<u64>(&[[0, 0, 0]], &mut []),
        Err(CodeError::LengthMismatch { src: 1, dst: 0 })
    );
}

proptest! {
    #[test]
    fn prop_u64_roundtrip(x in 0u32..1 << 21, y in 0u32..1 << 21, z in 0u32..1 << 21) {
        let c = encode(x, y, z);
        prop_assert_eq!(c, naive_encode::<u64>([x.into(), y.into(), z.into()]));
        prop_assert_eq!(decode(c), [x, y, z]);
        if Backend::Bmi2.is_available() {
            // SAFETY: availability checked.
            unsafe {
                prop_assert_eq!(<u64 as CodeWord>::encode_bmi2(x, y, z), c);
                prop_assert_eq!(c.decode_bmi2(), [x, y, z]);
            }
        }
    }

    #[test]
    fn prop_u128_roundtrip(x in 0u64..1 << 42, y in 0u64..1 << 42, z in 0u64..1 << 42) {
        let c = encode_wide(x, y, z);
        prop_assert_eq!(c, naive_encode::<u128>([x, y, z]));
        prop_assert_eq!(decode_wide(c), [x, y, z]);
        if Backend::Bmi2.is_available() {
            // SAFETY: availability checked.
            unsafe {
                prop_assert_eq!(<u128 as CodeWord>::encode_bmi2(x, y, z), c);
                prop_assert_eq!(c.decode_bmi2(), [x, y, z]);
            }
        }
    }
}

/// The naive model of a bounded space: decode, do integer arithmetic per axis, encode.
fn model_op<W: CodeWord>(
    space: &Space<W>,
    a: W,
    b: W,
    f: impl Fn(i128, i128) -> i128,
) -> Carried<W> {
    let d = space.depth();
    let side = 1i128 << d;
    let pa = naive_decode(a);
    let pb = naive_decode(b);
    let mut r = [0u64; 3];
    let mut carry = 0u8;
    for axis in 0..3 {
        let v = f(i128::from(pa[axis]), i128::from(pb[axis]));
        if !(0..side).contains(&v) {
            carry |= 1 << axis;
        }
        r[axis] = v.rem_euclid(side) as u64;
    }
    Carried {
        code: naive_encode(r),
        carry,
    }
}

fn signed_of(v: u64, d: u32) -> i128 {
    let v = i128::from(v);
    if d > 0 && v >= 1 << (d - 1) {
        v - (1 << d)
    } else {
        v
    }
}

fn check_arith<W: CodeWord>(seed: u64) {
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    for depth in 0..=W::MAX_DEPTH {
        let s = Space::<W>::new(depth).unwrap();
        for _ in 0..200 {
            let a: W = naive_encode(random_point(&mut rng, depth));
            let b: W = naive_encode(random_point(&mut rng, depth));
            // Junk above the space must be ignored.
            let junk = naive_encode::<W>(random_point(&mut rng, W::MAX_DEPTH)) & !s.mask();
            let (ja, jb) = (a | junk, b | junk);
            let ctx = format!("depth {depth} a {a:?} b {b:?} seed {seed:#x}");

            let add = model_op(&s, a, b, |x, y| x + y);
            let mut out = [W::ZERO; 1];
            batch::add_slices(&s, &[ja], &[jb], &mut out).unwrap();
            assert_eq!(out[0], add.code, "add_slices {ctx}");
            let mut moved = [ja];
            batch::translate_slice(&s, &mut moved, jb);
            assert_eq!(moved[0], add.code, "translate_slice {ctx}");
            assert_eq!(s.overflowing_add(ja, jb), add, "add {ctx}");
            assert_eq!(s.add(ja, jb), add.code, "add {ctx}");
            assert_eq!(add_by_table(a, b, depth), add, "table add {ctx}");
            assert_eq!(add_by_table_traced(a, b, depth).code, add.code);
            assert_eq!(s.checked_add(a, b), (add.carry == 0).then_some(add.code));

            let sub = model_op(&s, a, b, |x, y| x - y);
            assert_eq!(s.overflowing_sub(ja, jb), sub, "sub {ctx}");
            assert_eq!(s.sub(ja, jb), sub.code, "sub {ctx}");
            assert_eq!(s.checked_sub(a, b), (sub.carry == 0).then_some(sub.code));
            assert_eq!(s.neg(ja), model_op(&s, a, b, |x, _| -x).code, "neg {ctx}");
            assert_eq!(
                padic_sub(&s, a, b, false).result,
                sub.code,
                "padic unsigned {ctx}"
            );
            assert_eq!(
                padic_sub(&s, a, b, true).result,
                sub.code,
                "padic signed {ctx}"
            );

            for axis in Axis::ALL {
                let i = axis as usize;
                let unit = |x: i128, k: usize| if k == i { x + 1 } else { x };
                let pa = naive_decode(a);
                let mut up = pa.map(i128::from);
                up[i] = unit(up[i], i);
                let side = 1i128 << depth;
                let want_up: W = naive_encode(up.map(|v| v.rem_euclid(side) as u64));
                let r = s.overflowing_inc(ja, axis);
                assert_eq!(r.code, want_up, "inc {axis:?} {ctx}");
                assert_eq!(r.carry != 0, up[i] >= side, "inc carry {axis:?} {ctx}");
                assert_eq!(s.checked_inc(a, axis).is_some(), up[i] < side);
                let mut down = pa.map(i128::from);
                down[i] -= 1;
                let want_down: W = naive_encode(down.map(|v| v.rem_euclid(side) as u64));
                let r = s.overflowing_dec(ja, axis);
                assert_eq!(r.code, want_down, "dec {axis:?} {ctx}");
                assert_eq!(r.carry != 0, down[i] < 0, "dec borrow {axis:?} {ctx}");
                assert_eq!(s.checked_dec(a, axis).is_some(), down[i] >= 0);

                let pb = naive_decode(b);
                assert_eq!(s.cmp_axis(ja, jb, axis), pa[i].cmp(&pb[i]), "cmp {ctx}");
                assert_eq!(
                    s.cmp_axis_signed(ja, jb, axis),
                    signed_of(pa[i], depth).cmp(&signed_of(pb[i], depth)),
                    "cmp signed {ctx}"
                );
            }

            // Two's complement reading.
            let sa = naive_decode(a).map(|v| signed_of(v, depth));
            let sb = naive_decode(b).map(|v| signed_of(v, depth));
            assert_eq!(s.decode_signed(a).map(i128::from), sa);
            assert_eq!(s.encode_signed(sa.map(|v| v as i64)), Some(a));
            let fits = |v: i128| {
                if depth == 0 {
                    v == 0
                } else {
                    (-(1i128 << (depth - 1))..(1i128 << (depth - 1))).contains(&v)
                }
            };
            let sum_fits = (0..3).all(|k| fits(sa[k] + sb[k]));
            assert_eq!(
                s.checked_add_signed(a, b),
                sum_fits.then_some(add.code),
                "add signed {ctx}"
            );
            let diff_fits = (0..3).all(|k| fits(sa[k] - sb[k]));
            assert_eq!(
                s.checked_sub_signed(a, b),
                diff_fits.then_some(sub.code),
                "sub signed {ctx}"
            );
            let neg_fits = (0..3).all(|k| fits(-sa[k]));
            assert_eq!(
                s.checked_neg_signed(a),
                neg_fits.then_some(s.neg(a)),
                "neg signed {ctx}"
            );
            assert_eq!(s.decode_unsigned(a), naive_decode(a));
            assert_eq!(s.encode_unsigned(naive_decode(a)), Some(a));

            // P-adic in the signed reading: the repeating digit is the result's sign
            // digit whenever the difference fits.
            if diff_fits {
                let p = padic_sub(&s, a, b, true);
                assert_eq!(p.repeating_digits(), vec![s.sign_digit(sub.code)], "{ctx}");
                assert!(p.steps.len() <= depth as usize + 3);
            }
        }
    }
}

#[test]
fn arithmetic_u64_matches_model() {
    check_arith::<u64>(SEED ^ 1);
}

#[test]
fn arithmetic_u128_matches_model() {
    check_arith::<u128>(SEED ^ 2);
}

proptest! {
    #[test]
    fn prop_add_matches_table_adder(a in 0u64..1 << 63, b in 0u64..1 << 63, depth in 0u32..=21) {
        let s = Space::<u64>::new(depth).unwrap();
        let (a, b) = (a & s.mask(), b & s.mask());
        prop_assert_eq!(s.overflowing_add(a, b), add_by_table(a, b, depth));
        prop_assert_eq!(s.sub(s.add(a, b), b), a);
        prop_assert_eq!(s.add(a, s.neg(b)), s.sub(a, b));
    }
}

proptest! {
    #[test]
    fn prop_u128_space_matches_model(a: u128, b: u128, depth in 0u32..=42, axis in 0usize..3) {
        let s = Space::<u128>::new(depth).unwrap();
        let (a, b) = (a & s.mask(), b & s.mask());
        prop_assert_eq!(s.overflowing_add(a, b), model_op(&s, a, b, |x, y| x + y));
        prop_assert_eq!(s.overflowing_add(a, b), add_by_table(a, b, depth));
        prop_assert_eq!(s.overflowing_sub(a, b), model_op(&s, a, b, |x, y| x - y));
        prop_assert_eq!(padic_sub(&s, a, b, true).result, s.sub(a, b));
        let axis = Axis::ALL[axis];
        prop_assert_eq!(s.cmp_axis(a, b, axis), naive_decode(a)[axis as usize].cmp(&naive_decode(b)[axis as usize]));
        prop_assert_eq!(s.dec(s.inc(a, axis), axis), a);
    }
}

#[test]
fn space_limits() {
    assert_eq!(
        Space::<u64>::new(22),
        Err(CodeError::DepthTooLarge { depth: 22, max: 21 })
    );
    assert!(Space::<u128>::new(42).is_ok());
    assert!(Space::<u128>::new(43).is_err());
    assert_eq!(Space::<u64>::full().depth(), MAX_DEPTH_U64);
    assert_eq!(Space::<u128>::full().depth(), MAX_DEPTH_U128);
    let s = Space::<u64>::new(3).unwrap();
    assert!(s.contains(0o777));
    assert!(!s.contains(0o1000));
    assert_eq!(s.encode_signed([4, 0, 0]), None);
    assert_eq!(s.encode_signed([-4, 0, 0]), Some(0o100));
    assert_eq!(s.encode_unsigned([8, 0, 0]), None);
    // Depth 0: one cell; every step leaves it.
    let z = Space::<u64>::new(0).unwrap();
    assert_eq!(z.checked_inc(0, Axis::X), None);
    assert_eq!(z.checked_dec(0, Axis::Z), None);
    assert_eq!(z.add(5, 7), 0);
}

// ---- The papers' tables -----------------------------------------------------------

#[test]
#[allow(clippy::needless_range_loop)]
fn harakal_table1_is_the_definition_and_has_one_erratum() {
    // Spot entries read straight from the definition (per-axis sums).
    assert_eq!(ADD_TABLE[1][1], (1, 0));
    assert_eq!(ADD_TABLE[3][6], (2, 5));
    assert_eq!(ADD_TABLE[5][7], (5, 2));
    assert_eq!(ADD_TABLE[7][7], (7, 0));
    // docs/conventions.md erratum: row 5, column 5 printed 16; the sum 5 + 5 is 50.
    assert_eq!(ADD_TABLE[5][5], (5, 0));
    let t = &digits::harakal_tables()[0];
    let errata: Vec<_> = t
        .errata()
        .iter()
        .map(|&(r, c, cell)| (r, c, cell.printed.clone(), cell.value.clone()))
        .collect();
    assert_eq!(errata, vec![(5, 5, "16".to_owned(), "50".to_owned())]);
    // The table is symmetric, and 0 is the identity.
    for a in 0..8 {
        assert_eq!(ADD_TABLE[a][0], (0, a as u8));
        for b in 0..8 {
            assert_eq!(ADD_TABLE[a][b], ADD_TABLE[b][a]);
        }
    }
}

#[test]
#[allow(clippy::needless_range_loop)]
fn harakal_table2_inverts_table1_and_has_one_erratum() {
    for a in 0..8usize {
        for b in 0..8usize {
            let (carry, x) = SUB_TABLE[a][b];
            assert_eq!(
                ADD_TABLE[a][usize::from(x)],
                (carry, b as u8),
                "a {a} b {b}"
            );
        }
    }
    // Worked entries of the paper's example: (2 - 0) is (2, 2).
    assert_eq!(SUB_TABLE[2][0], (2, 2));
    assert_eq!(SUB_TABLE[6][3], (4, 5));
    // docs/conventions.md erratum: row 4, column 0 printed 2,2; the entry is 4,4.
    assert_eq!(SUB_TABLE[4][0], (4, 4));
    let t = &digits::harakal_tables()[1];
    let errata: Vec<_> = t
        .errata()
        .iter()
        .map(|&(r, c, cell)| (r, c, cell.printed.clone(), cell.value.clone()))
        .collect();
    assert_eq!(errata, vec![(4, 0, "2,2".to_owned(), "4,4".to_owned())]);
}

#[test]
fn ahuja_nash_tables_match_the_paper() {
    for t in digits::ahuja_nash_tables() {
        assert_eq!(t.rows.len(), 8);
        assert!(t.errata().is_empty(), "{} has an unexpected erratum", t.id);
    }
    // Table 1: even labels +1 along x, odd +7; y by 2 or 6; z always 4.
    for l in 0..8u8 {
        assert_eq!(
            digits::label_increment(l, Axis::X),
            if l % 2 == 0 { 1 } else { 7 }
        );
        assert_eq!(
            digits::label_increment(l, Axis::Y),
            if l & 2 == 0 { 2 } else { 6 }
        );
        assert_eq!(digits::label_increment(l, Axis::Z), 4);
    }
    // Table 2 entries with carry.
    assert_eq!(digits::label_transition(1, Axis::X), (true, 0));
    assert_eq!(digits::label_transition(3, Axis::Y), (true, 1));
    assert_eq!(digits::label_transition(7, Axis::Z), (true, 3));
    assert_eq!(digits::label_transition(2, Axis::X), (false, 3));
}

// ---- Worked examples ---------------------------------------------------------------

#[test]
fn ahuja_nash_worked_examples() {
    let s = Space::<u64>::new(3).unwrap();
    // r057 moved +1 along y: 7 + 1 gives 5 and a carry, then 5 becomes 7: r075.
    assert_eq!(s.inc(0o57, Axis::Y), 0o75);
    assert_eq!(
        s.overflowing_add(0o57, 0o002),
        Carried {
            code: 0o75,
            carry: 0
        }
    );
    // Moved +5 (binary 101) along y: 101 spread onto the y bits is 202: r275.
    assert_eq!(s.encode_wrapping([0, 5, 0]), 0o202);
    assert_eq!(
        s.overflowing_add(0o57, 0o202),
        Carried {
            code: 0o275,
            carry: 0
        }
    );
    // r275 moved -5 along y: 2's complement 011 spread is 022; r1057, carry lost.
    assert_eq!(s.neg(0o202), 0o022);
    assert_eq!(s.encode_wrapping([0, -5, 0]), 0o022);
    assert_eq!(
        s.overflowing_add(0o275, 0o022),
        Carried {
            code: 0o57,
            carry: Axis::Y.unit_digit()
        }
    );
    assert_eq!(s.checked_add(0o275, 0o022), None);
    // Read as two's complement the same sum is y: -2 + 3 = 1, no overflow at all.
    assert_eq!(s.checked_add_signed(0o275, 0o022), Some(0o57));
    assert_eq!(
        add_by_table(0o275u64, 0o022, 3),
        Carried {
            code: 0o57,
            carry: 2
        }
    );
    // The table adder's columns for r057 + 001 along y: 7 + 2 = 25 (digit 5, carry 2).
    let t = add_by_table_traced(0o57u64, 0o002, 3);
    assert_eq!(t.columns[0].first, (2, 5));
    assert_eq!(t.columns[1].carry_in, 2);
    assert_eq!(t.columns[1].digit, 7);
}

#[test]
fn harakal_worked_examples() {
    let s = Space::<u64>::full();
    assert_eq!(s.add(0o642, 0o752), 0o6530);
    assert_eq!(add_by_table(0o642u64, 0o752, 21).code, 0o6530);
    assert_eq!(s.sub(0o6530, 0o642), 0o752);
    // Their 45 is (3, 0, 1) with x in the high bit; ours is (1, 0, 3) (docs/conventions.md).
    assert_eq!(encode(1, 0, 3), 0o45);
}

#[test]
fn padic_subtraction_step_by_step() {
    let s = Space::<u64>::full();
    // 642 + T_x = 6530 (the paper's "642 - 6530", i.e. 6530 - 642).
    let p = padic_sub(&s, 0o6530, 0o642, true);
    let rows: Vec<(u64, u64, u8, u8, u8, u8)> = p
        .steps
        .iter()
        .map(|t| (t.ta, t.tb, t.a, t.b, t.carry, t.x))
        .collect();
    assert_eq!(
        rows,
        vec![
            // 2 - 0 is (2, 2): digit 2, carry 2; 64 + 2 = 66.
            (0o642, 0o6530, 2, 0, 2, 2),
            // 66 + T_x' = 653: (6 - 3) is (4, 5); 6 + 4 = 42.
            (0o66, 0o653, 6, 3, 4, 5),
            // 42 + T_x'' = 65: (2 - 5) is (2, 7); 4 + 2 = 6.
            (0o42, 0o65, 2, 5, 2, 7),
            // 6 + T_x''' = 6: digit 0, no carry.
            (0o6, 0o6, 6, 6, 0, 0),
            // 0 + T = 0: repeats from here on.
            (0, 0, 0, 0, 0, 0),
        ]
    );
    assert_eq!(p.repeat_from, 4);
    assert_eq!(p.result, 0o752);
    assert_eq!(format_padic(p.result, &s), "752");

    // The negative result: 752 - 6530 = …666062, the code of (0, -5, -6).
    let n = padic_sub(&s, 0o752, 0o6530, true);
    assert_eq!(n.repeating_digits(), vec![6]);
    assert_eq!(format_padic(n.result, &s), "...6062");
    assert_eq!(s.decode_signed(n.result), [0, -5, -6]);
    assert_eq!(s.decode_signed(0o642), [0, 5, 6]);
    let xs: Vec<u8> = n.steps.iter().map(|t| t.x).collect();
    // 6 + T = 0 gives digit 6 and carry 6, and 0 + 6 is 6 again: the equation
    // 6 + T = 0 comes back, so its digit 6 repeats forever.
    assert_eq!(xs, vec![2, 6, 0, 6]);
    assert_eq!(n.repeat_from, 3);
    // 0 - 1 = …7777 would be -1 on every axis: …1 only on x for 0 - 1 on x.
    assert_eq!(format_padic(padic_sub(&s, 0, 1, true).result, &s), "...1");
    assert_eq!(format_padic(padic_sub(&s, 0, 7, true).result, &s), "...7");
}

#[test]
fn notation_roundtrips_and_errors() {
    assert_eq!(parse_octal::<u64>("", 3), Err(ParseCodeError::Empty));
    assert_eq!(
        parse_octal::<u64>("158", 3),
        Err(ParseCodeError::InvalidDigit {
            found: '8',
            position: 3
        })
    );
    assert_eq!(
        parse_octal::<u64>("9", 3),
        Err(ParseCodeError::InvalidDigit {
            found: '9',
            position: 1
        })
    );
    assert_eq!(
        parse_octal::<u64>("0123", 3),
        Err(ParseCodeError::TooManyDigits { digits: 4, max: 3 })
    );
    assert_eq!(
        parse_octal::<u64>("x", 3),
        Err(ParseCodeError::InvalidDigit {
            found: 'x',
            position: 1
        })
    );
    assert_eq!(
        parse_octal::<u128>(&"7".repeat(42), 42),
        Ok((1u128 << 126) - 1)
    );
    let s = Space::<u128>::full();
    assert_eq!(parse_padic::<u128>("...", &s), Err(ParseCodeError::Empty));
    assert_eq!(
        parse_padic::<u128>("...8", &s),
        Err(ParseCodeError::InvalidDigit {
            found: '8',
            position: 4
        })
    );
    assert_eq!(
        parse_padic::<u128>("...69", &s),
        Err(ParseCodeError::InvalidDigit {
            found: '9',
            position: 5
        })
    );
    assert!(parse_padic::<u128>(&"1".repeat(42), &s).is_err());
    assert!(parse_padic::<u128>(&"1".repeat(41), &s).is_ok());
    let mut rng = Rng(SEED ^ 3);
    for _ in 0..2000 {
        let c = (u128::from(rng.next()) << 64 | u128::from(rng.next())) & s.mask();
        let text = format_padic(c, &s);
        assert_eq!(parse_padic(&text, &s), Ok(c), "{text}");
        let d = 1 + (rng.next() % 42) as u32;
        let c = c & Space::<u128>::new(d).unwrap().mask();
        assert_eq!(parse_octal(&format_padded(c, d), d), Ok(c));
    }
    assert_eq!(format_padic(0u128, &s), "0");
}

#[test]
fn cmp_axis_sorts_like_coordinates() {
    let s = Space::<u64>::new(4).unwrap();
    let mut codes: Vec<u64> = (0..4096).collect();
    codes.sort_by(|&a, &b| s.cmp_axis(a, b, Axis::Z).then(a.cmp(&b)));
    let zs: Vec<u32> = codes.iter().map(|&c| decode(c)[2]).collect();
    assert!(zs.windows(2).all(|w| w[0] <= w[1]));
    assert_eq!(s.cmp_axis(0o7, 0o7, Axis::X), Ordering::Equal);
}
