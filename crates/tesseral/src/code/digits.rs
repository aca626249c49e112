//! The papers' digit tables, computed, and the digit-by-digit table-driven adder.
//!
//! Harakal & Chmúrny §3 add tesseral numbers "by addition table lookup and by carry as
//! well as in ordinary arithmetic" (their Table 1) and subtract by the P-adic method
//! with a subtraction table (their Table 2). Ahuja & Nash §3.1 move a node by a unit
//! step with label increments (their Table 1) and label transitions with carry (their
//! Table 2). Every table here is computed from the definition (add the coordinates of
//! two cells axis by axis); the papers' printed entries are kept only to mark where the
//! print differs (two errata, docs/conventions.md). The adder here is slow on purpose: it is the
//! reference the word-parallel [`crate::code::Space::add`] is tested against, and the
//! trace `tesseral calc --explain` shows.

use serde::Serialize;

use super::{Axis, Carried, CodeWord};

/// A digit's bit for `axis`: 0 or 1.
const fn bit(d: u8, axis: u32) -> u8 {
    (d >> axis) & 1
}

/// The tesseral sum of two digits from the definition: add the two cells' x, y and z
/// offsets as integers (each 0 or 1), keep each sum's low bit in the digit and its
/// high bit in the carry. Returns `(carry, digit)`.
const fn digit_sum_by_axes(a: u8, b: u8) -> (u8, u8) {
    let mut carry = 0;
    let mut digit = 0;
    let mut axis = 0;
    while axis < 3 {
        let s = bit(a, axis) + bit(b, axis);
        digit |= (s % 2) << axis;
        carry |= (s / 2) << axis;
        axis += 1;
    }
    (carry, digit)
}

const fn build_add_table() -> [[(u8, u8); 8]; 8] {
    let mut t = [[(0, 0); 8]; 8];
    let mut a = 0;
    while a < 8 {
        let mut b = 0;
        while b < 8 {
            t[a][b] = digit_sum_by_axes(a as u8, b as u8);
            b += 1;
        }
        a += 1;
    }
    t
}

/// Harakal & Chmúrny Table 1, computed: `ADD_TABLE[a][b] = (carry, digit)` of the
/// tesseral sum `a + b`. Their printed entry "52" for 5 + 7 is `(5, 2)`.
pub const ADD_TABLE: [[(u8, u8); 8]; 8] = build_add_table();

const fn build_sub_table() -> [[(u8, u8); 8]; 8] {
    // Their method: find the digit x that, added to a, gives b ("a glance at the
    // addition table"); the carry of that sum goes onto the remaining digits of a.
    let mut t = [[(0, 0); 8]; 8];
    let mut a = 0;
    while a < 8 {
        let mut b = 0;
        while b < 8 {
            let mut x = 0;
            while x < 8 {
                if ADD_TABLE[a][x].1 == b as u8 {
                    t[a][b] = (ADD_TABLE[a][x].0, x as u8);
                }
                x += 1;
            }
            b += 1;
        }
        a += 1;
    }
    t
}

/// Harakal & Chmúrny Table 2, computed: `SUB_TABLE[a][b] = (carry, x)` where `x` is
/// the digit with `a + x` ending in `b`, and `carry` is that sum's carry, to be added
/// to the remaining digits of `a` (the P-adic method). Row `a` is the subtrahend's
/// digit `T_a`, column `b` the minuend's digit `T_b`.
pub const SUB_TABLE: [[(u8, u8); 8]; 8] = build_sub_table();

/// Ahuja & Nash Table 1, computed: the label increment (modulo 8) of a node labelled
/// `label` moved one unit along `axis`.
///
/// ```
/// use tesseral::code::{digits, Axis};
/// assert_eq!(digits::label_increment(1, Axis::X), 7);
/// assert_eq!(digits::label_increment(2, Axis::Y), 6);
/// ```
#[must_use]
pub const fn label_increment(label: u8, axis: Axis) -> u8 {
    let (_, new) = ADD_TABLE[(label & 7) as usize][axis.unit_digit() as usize];
    new.wrapping_sub(label & 7) & 7
}

/// Ahuja & Nash Table 2, computed: the new label of a node labelled `label` moved one
/// unit along `axis`, and whether its parent must move too (their "carry", a 1 written
/// left of the label).
///
/// ```
/// use tesseral::code::{digits, Axis};
/// assert_eq!(digits::label_transition(7, Axis::X), (true, 6)); // printed "16"
/// ```
#[must_use]
pub const fn label_transition(label: u8, axis: Axis) -> (bool, u8) {
    let (carry, new) = ADD_TABLE[(label & 7) as usize][axis.unit_digit() as usize];
    (carry != 0, new)
}

/// One column of the digit-by-digit addition: `a + b + carry_in`, done as two lookups
/// in Harakal & Chmúrny Table 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct AddColumn {
    /// Digit position, 0 for the least significant (the leaf's label).
    pub position: u32,
    /// The digit of the first operand.
    pub a: u8,
    /// The digit of the second operand.
    pub b: u8,
    /// The carry digit coming in from the position below.
    pub carry_in: u8,
    /// `ADD_TABLE[a][b]`: `(carry, digit)` of `a + b`.
    pub first: (u8, u8),
    /// `ADD_TABLE[first.1][carry_in]`: `(carry, digit)` of adding the carry in.
    pub second: (u8, u8),
    /// The result digit (`second.1`).
    pub digit: u8,
    /// The carry digit going out: `first.0 + second.0`, which never carries again.
    pub carry_out: u8,
}

/// A digit-by-digit sum with its columns, least significant first.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct DigitSum<W> {
    /// One entry per digit of the space.
    pub columns: Vec<AddColumn>,
    /// The sum, reduced to the space.
    pub code: W,
    /// The carry digit out of the top digit, lost in a bounded space.
    pub carry: u8,
}

#[inline]
fn add_column(a: u8, b: u8, carry_in: u8) -> ((u8, u8), (u8, u8), u8) {
    let first = ADD_TABLE[usize::from(a)][usize::from(b)];
    let second = ADD_TABLE[usize::from(first.1)][usize::from(carry_in)];
    // Per axis a + b + carry <= 3, so the two partial carries never share an axis and
    // their tesseral sum has no carry of its own.
    let (overflow, carry_out) = ADD_TABLE[usize::from(first.0)][usize::from(second.0)];
    debug_assert_eq!(overflow, 0);
    (first, second, carry_out)
}

/// Adds two codes of `depth` digits by table lookup, one digit at a time from the
/// least significant, as Harakal & Chmúrny §3 and Ahuja & Nash §3.1 do by hand.
/// O(depth). The reference for [`crate::code::Space::overflowing_add`].
///
/// ```
/// use tesseral::code::digits::add_by_table;
/// let r = add_by_table::<u64>(0o275, 0o022, 3);
/// assert_eq!((r.code, r.carry), (0o057, 2)); // Ahuja & Nash: "r1057, carry lost"
/// ```
#[must_use]
pub fn add_by_table<W: CodeWord>(a: W, b: W, depth: u32) -> Carried<W> {
    let depth = depth.min(W::MAX_DEPTH);
    let mut code = W::ZERO;
    let mut carry = 0;
    for i in 0..depth {
        let (_, second, out) = add_column(
            (a >> (3 * i)).low_digit(),
            (b >> (3 * i)).low_digit(),
            carry,
        );
        code = code | (W::from_digit(second.1) << (3 * i));
        carry = out;
    }
    Carried { code, carry }
}

/// [`add_by_table`] with every column recorded, for teaching (`calc --explain`).
/// O(depth).
#[must_use]
pub fn add_by_table_traced<W: CodeWord>(a: W, b: W, depth: u32) -> DigitSum<W> {
    let depth = depth.min(W::MAX_DEPTH);
    let mut columns = Vec::with_capacity(depth as usize);
    let mut code = W::ZERO;
    let mut carry = 0;
    for i in 0..depth {
        let (da, db) = ((a >> (3 * i)).low_digit(), (b >> (3 * i)).low_digit());
        let (first, second, out) = add_column(da, db, carry);
        columns.push(AddColumn {
            position: i,
            a: da,
            b: db,
            carry_in: carry,
            first,
            second,
            digit: second.1,
            carry_out: out,
        });
        code = code | (W::from_digit(second.1) << (3 * i));
        carry = out;
    }
    DigitSum {
        columns,
        code,
        carry,
    }
}

/// One cell of a paper's table: the computed entry and what the paper printed.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct TableCell {
    /// The entry computed from the definition.
    pub value: String,
    /// The entry as the paper printed it.
    pub printed: String,
    /// Whether the paper's entry is wrong (`printed != value`).
    pub erratum: bool,
}

/// One row of a paper's table.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct TableRow {
    /// The row header (a label or a digit).
    pub label: String,
    /// The cells, one per column.
    pub cells: Vec<TableCell>,
}

/// A table from one of the papers, computed, with the paper's print alongside.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct PaperTable {
    /// Short identifier, e.g. `"harakal-1"`.
    pub id: &'static str,
    /// The paper and table, e.g. "Harakal & Chmúrny, Table 1".
    pub source: &'static str,
    /// The table's caption as the paper gives it.
    pub title: &'static str,
    /// How to read an entry.
    pub legend: &'static str,
    /// Header of the row-label column.
    pub corner: &'static str,
    /// Column headers.
    pub columns: Vec<String>,
    /// The rows.
    pub rows: Vec<TableRow>,
    /// Notes printed under the table: errata of the paper's text near it.
    pub notes: Vec<&'static str>,
}

/// Harakal & Chmúrny §2, eq. (1), checked by counting the nodes of full octrees
/// (`linear::node_list` tests).
pub const HC_EQ1_ERRATUM: &str = "Eq. (1), §2: the paper gives the node count of a full \
     octree of depth n as (8^n + 1)/7; the sum it writes, 1 + 8 + ... + 8^n, is \
     (8^(n+1) - 1)/7 (n = 2: 73 nodes, not 9.29).";

impl PaperTable {
    /// The cells where the paper printed something else: `(row, column, cell)`.
    #[must_use]
    pub fn errata(&self) -> Vec<(usize, usize, &TableCell)> {
        let mut out = Vec::new();
        for (r, row) in self.rows.iter().enumerate() {
            for (c, cell) in row.cells.iter().enumerate() {
                if cell.erratum {
                    out.push((r, c, cell));
                }
            }
        }
        out
    }
}

fn cell(value: String, printed: &str) -> TableCell {
    TableCell {
        erratum: value != printed,
        value,
        printed: printed.to_owned(),
    }
}

/// Harakal & Chmúrny Table 1 as printed (for marking errata only).
const HC1_PRINTED: [[&str; 8]; 8] = [
    ["00", "01", "02", "03", "04", "05", "06", "07"],
    ["01", "10", "03", "12", "05", "14", "07", "16"],
    ["02", "03", "20", "21", "06", "07", "24", "25"],
    ["03", "12", "21", "30", "07", "16", "25", "34"],
    ["04", "05", "06", "07", "40", "41", "42", "43"],
    ["05", "14", "07", "16", "41", "16", "43", "52"],
    ["06", "07", "24", "25", "42", "43", "60", "61"],
    ["07", "16", "25", "34", "43", "52", "61", "70"],
];

/// Harakal & Chmúrny Table 2 as printed (for marking errata only).
const HC2_PRINTED: [[&str; 8]; 8] = [
    ["0,0", "0,1", "0,2", "0,3", "0,4", "0,5", "0,6", "0,7"],
    ["1,1", "0,0", "1,3", "0,2", "1,5", "0,4", "1,7", "0,6"],
    ["2,2", "2,3", "0,0", "0,1", "2,6", "2,7", "0,4", "0,5"],
    ["3,3", "2,2", "1,1", "0,0", "3,7", "2,6", "1,5", "0,4"],
    ["2,2", "4,5", "4,6", "4,7", "0,0", "0,1", "0,2", "0,3"],
    ["5,5", "4,4", "5,7", "4,6", "1,1", "0,0", "1,3", "0,2"],
    ["6,6", "6,7", "4,4", "4,5", "2,2", "2,3", "0,0", "0,1"],
    ["7,7", "6,6", "5,5", "4,4", "3,3", "2,2", "1,1", "0,0"],
];

/// Ahuja & Nash Table 1 as printed (for marking errata only).
const AN1_PRINTED: [[&str; 3]; 8] = [
    ["+1", "+2", "+4"],
    ["+7", "+2", "+4"],
    ["+1", "+6", "+4"],
    ["+7", "+6", "+4"],
    ["+1", "+2", "+4"],
    ["+7", "+2", "+4"],
    ["+1", "+6", "+4"],
    ["+7", "+6", "+4"],
];

/// Ahuja & Nash Table 2 as printed (for marking errata only).
const AN2_PRINTED: [[&str; 3]; 8] = [
    ["1", "2", "4"],
    ["10", "3", "5"],
    ["3", "10", "6"],
    ["12", "11", "7"],
    ["5", "6", "10"],
    ["14", "7", "11"],
    ["7", "14", "12"],
    ["16", "15", "13"],
];

fn axis_columns() -> Vec<String> {
    vec!["+X".into(), "+Y".into(), "+Z".into()]
}

fn digit_columns() -> Vec<String> {
    (0..8).map(|d| d.to_string()).collect()
}

/// Ahuja & Nash §3.1 Tables 1 and 2, computed.
#[must_use]
pub fn ahuja_nash_tables() -> Vec<PaperTable> {
    let t1 = PaperTable {
        id: "ahuja-nash-1",
        source: "Ahuja & Nash 1983, §3.1, Table 1",
        title: "Label increments (modulo 8) representing unit displacements",
        legend: "increment of a node's label after a unit displacement along the axis",
        corner: "label",
        columns: axis_columns(),
        rows: (0..8u8)
            .map(|l| TableRow {
                label: l.to_string(),
                cells: Axis::ALL
                    .iter()
                    .zip(AN1_PRINTED[usize::from(l)])
                    .map(|(&axis, p)| cell(format!("+{}", label_increment(l, axis)), p))
                    .collect(),
            })
            .collect(),
        notes: Vec::new(),
    };
    let t2 = PaperTable {
        id: "ahuja-nash-2",
        source: "Ahuja & Nash 1983, §3.1, Table 2",
        title: "Label transitions representing unit displacements",
        legend: "final label; a 1 on its left is the carry: the parent moves too",
        corner: "label",
        columns: axis_columns(),
        rows: (0..8u8)
            .map(|l| TableRow {
                label: l.to_string(),
                cells: Axis::ALL
                    .iter()
                    .zip(AN2_PRINTED[usize::from(l)])
                    .map(|(&axis, p)| {
                        let (carry, new) = label_transition(l, axis);
                        let v = if carry {
                            format!("1{new}")
                        } else {
                            new.to_string()
                        };
                        cell(v, p)
                    })
                    .collect(),
            })
            .collect(),
        notes: Vec::new(),
    };
    let t3 = PaperTable {
        id: "harakal-mul",
        source: "Harakal & Chmúrny, §3 (a table not in the paper: defined in docs/arithmetic.md)",
        title: "Octree tesseral digit multiplication, axis by axis",
        legend: "row * column: each axis bit multiplied, so the digit product is the bitwise AND; no carry",
        corner: "*",
        columns: digit_columns(),
        rows: (0..8u8)
            .map(|a| TableRow {
                label: a.to_string(),
                cells: (0..8u8)
                    .map(|b| {
                        let v = (a & b).to_string();
                        cell(v.clone(), &v)
                    })
                    .collect(),
            })
            .collect(),
        notes: vec![
            "A code times a code shifts and adds these rows with Table 1: see `tesseral calc mul --explain`.",
        ],
    };
    vec![t1, t2, t3]
}

/// Harakal & Chmúrny §3 Tables 1 and 2, computed; the two errata are marked.
#[must_use]
pub fn harakal_tables() -> Vec<PaperTable> {
    let t1 = PaperTable {
        id: "harakal-1",
        source: "Harakal & Chmúrny, §3, Table 1",
        title: "Octree tesseral digit addition",
        legend: "row + column, written as carry digit then sum digit",
        corner: "+",
        columns: digit_columns(),
        rows: (0..8usize)
            .map(|a| TableRow {
                label: a.to_string(),
                cells: (0..8usize)
                    .map(|b| {
                        let (c, d) = ADD_TABLE[a][b];
                        cell(format!("{c}{d}"), HC1_PRINTED[a][b])
                    })
                    .collect(),
            })
            .collect(),
        notes: vec![HC_EQ1_ERRATUM],
    };
    let t2 = PaperTable {
        id: "harakal-2",
        source: "Harakal & Chmúrny, §3, Table 2",
        title: "Octree tesseral digit subtraction",
        legend: "row = digit of T_a, column = digit of T_b; entry \"carry, digit\" of T_x \
                 with T_a + T_x = T_b; the carry is added to the remaining digits of T_a",
        corner: "Ta\\Tb",
        columns: digit_columns(),
        rows: (0..8usize)
            .map(|a| TableRow {
                label: a.to_string(),
                cells: (0..8usize)
                    .map(|b| {
                        let (c, x) = SUB_TABLE[a][b];
                        cell(format!("{c},{x}"), HC2_PRINTED[a][b])
                    })
                    .collect(),
            })
            .collect(),
        notes: Vec::new(),
    };
    let t3 = PaperTable {
        id: "harakal-mul",
        source: "Harakal & Chmúrny, §3 (a table not in the paper: defined in docs/arithmetic.md)",
        title: "Octree tesseral digit multiplication, axis by axis",
        legend: "row * column: each axis bit multiplied, so the digit product is the bitwise AND; no carry",
        corner: "*",
        columns: digit_columns(),
        rows: (0..8u8)
            .map(|a| TableRow {
                label: a.to_string(),
                cells: (0..8u8)
                    .map(|b| {
                        let v = (a & b).to_string();
                        cell(v.clone(), &v)
                    })
                    .collect(),
            })
            .collect(),
        notes: vec![
            "A code times a code shifts and adds these rows with Table 1: see `tesseral calc mul --explain`.",
        ],
    };
    vec![t1, t2, t3]
}
