//! The papers' tables (computed, with their two errata) and worked examples.

use super::*;

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
