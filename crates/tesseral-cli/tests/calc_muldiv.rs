//! Runs the real `tesseral` binary: `calc mul`, `calc div`, `calc qmul`, the digit
//! multiplication table and the papers' notations of `info` (issue 16 §1 and §4).

use std::process::Output;

mod common;

fn run(args: &[&str]) -> Output {
    let dir = tempfile::tempdir().expect("temp dir");
    common::run(dir.path(), args)
}

fn ok(args: &[&str]) -> String {
    let o = run(args);
    assert!(
        o.status.success(),
        "{args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).expect("utf-8 stdout")
}

/// A command that must fail with exit code 2 and one line naming `names`.
fn bad(args: &[&str], names: &str) {
    let o = run(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(o.stdout.is_empty(), "{args:?} printed to stdout");
    assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    assert!(err.contains(names), "{args:?}: {err} does not name {names}");
}

fn code(p: [i64; 3]) -> String {
    ok(&[
        "calc",
        "encode",
        &p[0].to_string(),
        &p[1].to_string(),
        &p[2].to_string(),
    ])
    .trim()
    .to_owned()
}

#[test]
fn multiplication_scales_axis_by_axis() {
    assert_eq!(ok(&["calc", "mul", "642", "7"]), "642\n");
    assert_eq!(ok(&["calc", "mul", "642", "70"]), "6420\n");
    let a = code([3, -2, 5]);
    let b = code([-4, 7, 1]);
    assert_eq!(ok(&["calc", "mul", &a, &b]).trim(), code([-12, -14, 5]));
    // Bounded: the carry is dropped and reported on stderr, as for add.
    let o = run(&["calc", "mul", "642", "752", "--digits", "4"]);
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("carry"));
    let explained = ok(&["calc", "mul", "642", "752", "--explain"]);
    assert!(
        explained.contains("digit 2 = 5 (along x, z)"),
        "{explained}"
    );
    bad(&["calc", "mul", "189", "1"], "argument A");
    bad(
        &[
            "calc",
            "mul",
            &code([1 << 30, 0, 0]),
            &code([1 << 30, 0, 0]),
        ],
        "out of range",
    );
}

#[test]
fn division_is_exact_or_repeats() {
    let (b, a) = (code([-12, 6, 4]), code([-4, 3, 2]));
    assert_eq!(ok(&["calc", "div", &b, &a]).trim(), code([3, 2, 2]));
    assert_eq!(ok(&["calc", "div", "6530", "70"]), "653\n");
    // 1/3 along x (y and z divide 0 by 1): ...010101011 in binary.
    let three = code([3, 1, 1]);
    assert_eq!(ok(&["calc", "div", "1", &three]), "...[01]1\n");
    let explained = ok(&["calc", "div", "1", &three, "--explain"]);
    assert!(
        explained.contains("repeat from digit 2 with period 2"),
        "{explained}"
    );
    // Bounded: the quotient modulo 8^N, 1/3 = 43 = 101011 in binary along x.
    assert_eq!(
        ok(&["calc", "div", "1", &three, "--digits", "6"]),
        "101011\n"
    );
    let json = ok(&["calc", "div", "1", &three, "--json"]);
    assert!(json.contains(r#""result":"...[01]1""#), "{json}");
    bad(&["calc", "div", "7", "3"], "division by zero along z");
    bad(
        &["calc", "div", &code([1, 1, 1]), &code([2, 1, 1])],
        "along x: the divisor is even",
    );
    bad(&["calc", "div", "7", "9"], "argument A");
}

#[test]
fn quaternions_rotate_and_scale() {
    // 1 + k: a quarter turn about z, times 2: (1, 0, 0) -> (0, 2, 0).
    assert_eq!(
        ok(&["calc", "qmul", "1", "1,0,0,1"]).trim(),
        code([0, 2, 0])
    );
    let json = ok(&["calc", "qmul", &code([1, 2, 3]), "1,1,1,1", "--json"]);
    // (1 + i + j + k)/2 turns x -> y -> z -> x; times 4.
    assert!(json.contains(r#""coordinates":[12,4,8]"#), "{json}");
    let explained = ok(&["calc", "qmul", "1", "0,1,0,0", "--explain"]);
    assert!(explained.contains("rotation by 180.0000°"), "{explained}");
    bad(&["calc", "qmul", "1", "1,2,3"], "argument Q");
    bad(&["calc", "qmul", "1", "0,0,0,0"], "argument Q");
}

#[test]
fn tables_print_the_digit_multiplication_table_and_eq_1() {
    let text = ok(&["tables", "harakal"]);
    assert!(text.contains("digit multiplication"), "{text}");
    assert!(text.contains("(8^(n+1) - 1)/7"), "{text}");
    let json = ok(&["tables", "harakal", "--json"]);
    assert!(json.contains("harakal-mul"));
}

#[test]
fn info_prints_the_papers_notations() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("t.xyz"), "0 0 0\n1 0 0\n3 3 3\n").unwrap();
    let tree = common::ok(d, &["info", "t.xyz", "--tree"]);
    assert_eq!(
        tree,
        "r gray\n  r0 gray\n    r00 black\n    r01 black\n  r7 gray\n    r77 black\n"
    );
    assert_eq!(common::ok(d, &["info", "t.xyz", "--codes"]), "00\n01\n77\n");
    let json = common::ok(d, &["info", "t.xyz", "--codes", "--json"]);
    assert_eq!(json.trim(), r#"{"codes":["00","01","77"]}"#);
    let json = common::ok(d, &["info", "t.xyz", "--tree", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["nodes"].as_array().unwrap().len(), 6);
    assert_eq!(v["nodes"][2]["colour"], "black");
}
