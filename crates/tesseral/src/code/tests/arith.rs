//! `Space` arithmetic against the decode-compute-encode model, both widths.

use super::*;

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

#[test]
fn cmp_axis_sorts_like_coordinates() {
    let s = Space::<u64>::new(4).unwrap();
    let mut codes: Vec<u64> = (0..4096).collect();
    codes.sort_by(|&a, &b| s.cmp_axis(a, b, Axis::Z).then(a.cmp(&b)));
    let zs: Vec<u32> = codes.iter().map(|&c| decode(c)[2]).collect();
    assert!(zs.windows(2).all(|w| w[0] <= w[1]));
    assert_eq!(s.cmp_axis(0o7, 0o7, Axis::X), Ordering::Equal);
}
