//! Runs the real `tesseral` binary: `calc` and `tables`, good and bad input.

use std::process::Output;

mod common;

/// Runs `tesseral args...` in a fresh temporary directory.
fn run(args: &[&str]) -> Output {
    let dir = tempfile::tempdir().expect("temp dir");
    common::run(dir.path(), args)
}

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("utf-8 stdout")
}

fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).expect("utf-8 stderr")
}

/// Runs a command that must succeed and returns its stdout.
fn ok(args: &[&str]) -> String {
    let o = run(args);
    assert!(o.status.success(), "{args:?} failed: {}", stderr(&o));
    stdout(&o)
}

/// Runs a command that must fail with exit code 2, a one-line error naming `names`,
/// and no panic.
fn bad(args: &[&str], names: &str) {
    let o = run(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(stdout(&o).is_empty(), "{args:?} printed to stdout");
    assert_eq!(err.lines().count(), 1, "{args:?}: not one line: {err}");
    assert!(err.starts_with("error: "), "{args:?}: {err}");
    assert!(err.contains(names), "{args:?}: {err} does not name {names}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
}

#[test]
fn the_issue_examples() {
    let cases: &[(&[&str], &str)] = &[
        (&["calc", "add", "642", "752"], "6530\n"),
        (&["calc", "sub", "6530", "642"], "752\n"),
        (&["calc", "encode", "1", "0", "3"], "45\n"),
        (&["calc", "decode", "45"], "1 0 3\n"),
        (&["calc", "add", "057", "002", "--digits", "3"], "075\n"),
        (&["calc", "add", "057", "202", "--digits", "3"], "275\n"),
        (&["calc", "add", "275", "022", "--digits", "3"], "057\n"),
    ];
    for (args, want) in cases {
        assert_eq!(ok(args), *want, "{args:?}");
    }
}

#[test]
fn lost_carry_is_reported_on_stderr_only_when_lost() {
    let o = run(&["calc", "add", "275", "022", "--digits", "3"]);
    assert!(o.status.success());
    assert_eq!(stdout(&o), "057\n");
    let err = stderr(&o);
    assert!(
        err.contains("carry 2 lost") && err.contains("along y"),
        "{err}"
    );
    let o = run(&["calc", "add", "057", "202", "--digits", "3"]);
    assert!(stderr(&o).is_empty());
    let o = run(&["calc", "sub", "642", "6530", "--digits", "4"]);
    assert_eq!(stdout(&o), "7072\n");
    assert!(stderr(&o).contains("borrow 7 lost"), "{}", stderr(&o));
}

#[test]
fn negative_codes_in_the_hypercube() {
    assert_eq!(ok(&["calc", "sub", "752", "6530"]), "...6062\n");
    assert_eq!(ok(&["calc", "neg", "642"]), "...6062\n");
    assert_eq!(ok(&["calc", "decode", "...6062"]), "0 -5 -6\n");
    assert_eq!(ok(&["calc", "encode", "0", "-5", "-6"]), "...6062\n");
    assert_eq!(ok(&["calc", "encode", "-1", "0", "0"]), "...1\n");
    assert_eq!(ok(&["calc", "add", "...6062", "642"]), "0\n");
    assert_eq!(ok(&["calc", "neg", "...6062"]), "642\n");
    // Ahuja & Nash: -5 in three binary digits is 011, spread on y: 022.
    assert_eq!(
        ok(&["calc", "encode", "0", "-5", "0", "--digits", "3"]),
        "022\n"
    );
    assert_eq!(ok(&["calc", "neg", "202", "--digits", "3"]), "022\n");
    assert_eq!(ok(&["calc", "decode", "022", "--digits", "3"]), "0 3 0\n");
    // Flags may come before the operation too.
    assert_eq!(ok(&["calc", "--digits", "3", "add", "057", "002"]), "075\n");
}

#[test]
fn explain_shows_the_work() {
    let add = ok(&["calc", "add", "642", "752", "--explain"]);
    assert!(
        add.contains("digit 1: 4 + 5 = 41; 1 + carry 2 = 03 -> digit 3, carry 4"),
        "{add}"
    );
    assert!(add.ends_with("\n6530\n"), "{add}");
    let lost = ok(&["calc", "add", "275", "022", "--digits", "3", "--explain"]);
    assert!(lost.contains("carry 2 out of digit 2 is lost"), "{lost}");
    let sub = ok(&["calc", "sub", "6530", "642", "--explain"]);
    for line in [
        "642 + T = 6530",
        "Table 2 [2][0] = 2,2: digit 2, carry 2",
        "66 + T' = 653",
        "Table 2 [6][3] = 4,5: digit 5, carry 4",
        "42 + T'' = 65",
        "its digit 0 repeats forever",
    ] {
        assert!(sub.contains(line), "missing {line:?} in\n{sub}");
    }
    assert!(sub.ends_with("\n752\n"));
    let neg = ok(&["calc", "sub", "752", "6530", "--explain"]);
    assert!(neg.contains("6 + T''' = 0"), "{neg}");
    assert!(neg.contains("its digit 6 repeats forever"), "{neg}");
    assert!(neg.ends_with("\n...6062\n"));
    let n = ok(&["calc", "neg", "642", "--explain"]);
    assert!(n.contains("complement of 642 is ...7135"), "{n}");
    let e = ok(&["calc", "encode", "1", "0", "3", "--explain"]);
    assert!(e.contains("digit 1: z 1 y 0 x 0 -> 4"), "{e}");
    assert!(e.ends_with("\n45\n"));
    let d = ok(&["calc", "decode", "45", "--explain"]);
    assert!(d.ends_with("\n1 0 3\n"), "{d}");
}

#[test]
fn bad_codes_name_the_argument() {
    for (args, name) in [
        (&["calc", "add", "189", "1"][..], "argument A"),
        (&["calc", "add", "1", "9"], "argument B"),
        (&["calc", "add", "", "1"], "argument A"),
        (&["calc", "add", "1", ""], "argument B"),
        (&["calc", "add", "abc", "1"], "argument A"),
        (&["calc", "add", "1", "1.5"], "argument B"),
        (&["calc", "sub", "8", "1"], "argument A"),
        (&["calc", "sub", "1", "x"], "argument B"),
        (&["calc", "neg", "9"], "argument A"),
        (&["calc", "neg", ""], "argument A"),
        (&["calc", "decode", "78"], "argument CODE"),
        (&["calc", "decode", ""], "argument CODE"),
        (&["calc", "decode", "-1"], "argument CODE"),
        (&["calc", "decode", "...8"], "argument CODE"),
        (&["calc", "decode", "..."], "argument CODE"),
        (&["calc", "add", "1234", "1", "--digits", "3"], "argument A"),
        (&["calc", "add", "1", "0001", "--digits", "3"], "argument B"),
        (&["calc", "decode", "12", "--digits", "1"], "argument CODE"),
        (&["calc", "neg", &"1".repeat(42)], "argument A"),
        (&["calc", "add", &"1".repeat(100), "1"], "argument A"),
    ] {
        bad(args, name);
    }
    let o = run(&["calc", "add", "189", "1"]);
    assert!(stderr(&o).contains("'8'"), "{}", stderr(&o));
    let o = run(&["calc", "add", "1234", "1", "--digits", "3"]);
    assert!(stderr(&o).contains("4 digits"), "{}", stderr(&o));
}

#[test]
fn bad_coordinates_and_digits_name_the_argument() {
    for (args, name) in [
        (&["calc", "encode", "a", "0", "0"][..], "argument X"),
        (&["calc", "encode", "0", "", "0"], "argument Y"),
        (&["calc", "encode", "0", "0", "1e3"], "argument Z"),
        (
            &["calc", "encode", "99999999999999999999", "0", "0"],
            "argument X",
        ),
        (&["calc", "encode", "0", "2199023255552", "0"], "argument Y"),
        (
            &["calc", "encode", "0", "0", "8", "--digits", "3"],
            "argument Z",
        ),
        (
            &["calc", "encode", "-8", "0", "0", "--digits", "3"],
            "argument X",
        ),
        (
            &["calc", "add", "1", "1", "--digits", "0"],
            "argument --digits",
        ),
        (
            &["calc", "add", "1", "1", "--digits", "43"],
            "argument --digits",
        ),
        (
            &["calc", "add", "1", "1", "--digits", "abc"],
            "argument --digits",
        ),
        (
            &["calc", "add", "1", "1", "--digits", ""],
            "argument --digits",
        ),
        (
            &["calc", "add", "1", "1", "--digits", "-3"],
            "argument --digits",
        ),
        (&["tables", "quaternions"], "argument PAPER"),
    ] {
        bad(args, name);
    }
    // The largest values that fit still work.
    assert_eq!(
        ok(&["calc", "encode", "0", "2199023255551", "0"]),
        format!("{}\n", "2".repeat(41))
    );
    assert_eq!(
        ok(&["calc", "encode", "-7", "7", "0", "--digits", "3"]),
        "223\n"
    );
}

#[test]
fn overflow_in_the_hypercube_is_an_error() {
    let big = "7".repeat(41);
    let o = run(&["calc", "add", &big, "1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("out of range"), "{}", stderr(&o));
    assert_eq!(stderr(&o).lines().count(), 1);
}

#[test]
fn tables_text_marks_the_errata() {
    let h = ok(&["tables", "harakal"]);
    assert!(h.contains("Table 1") && h.contains("Table 2"), "{h}");
    assert!(h.contains("50*1"), "{h}");
    assert!(h.contains("*1 row 5, column 5: the paper prints 16"), "{h}");
    assert!(h.contains("4,4*1"), "{h}");
    assert!(
        h.contains("*1 row 4, column 0: the paper prints 2,2"),
        "{h}"
    );
    assert_eq!(h.matches("the paper prints").count(), 2);
    let a = ok(&["tables", "ahuja-nash"]);
    assert!(a.contains("+X") && a.contains("16"), "{a}");
    assert!(!a.contains("the paper prints"), "{a}");
    let both = ok(&["tables"]);
    assert!(both.contains("Ahuja & Nash") && both.contains("Harakal"));
}

#[test]
fn tables_json() {
    let text = ok(&["tables", "harakal", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
    let tables = v["tables"].as_array().expect("tables array");
    assert_eq!(
        tables.len(),
        3,
        "tables 1, 2 and the digit multiplication table"
    );
    let cell = &tables[0]["rows"][5]["cells"][5];
    assert_eq!(cell["value"], "50");
    assert_eq!(cell["printed"], "16");
    assert_eq!(cell["erratum"], true);
    let cell = &tables[1]["rows"][4]["cells"][0];
    assert_eq!(cell["value"], "4,4");
    assert_eq!(cell["printed"], "2,2");
    let errata: usize = tables
        .iter()
        .flat_map(|t| t["rows"].as_array().unwrap())
        .flat_map(|r| r["cells"].as_array().unwrap())
        .filter(|c| c["erratum"] == true)
        .count();
    assert_eq!(errata, 2);
    let a: serde_json::Value =
        serde_json::from_str(&ok(&["tables", "ahuja-nash", "--json"])).unwrap();
    assert_eq!(a["tables"][1]["rows"][7]["cells"][0]["value"], "16");
}
