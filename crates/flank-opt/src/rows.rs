//! Blade rows: which rows a blade operation machines (`rows = ["main", "splitter"]`), the
//! reference blade of each, its neighbours and the rotational copies of its paths.
//!
//! Each row is planned on its reference blade (instance 0 of the main blades, or of the
//! splitters, which sits between main blades 0 and 1) and the paths are copied to every
//! blade of the row by rotation about the impeller axis ([`cam_plan::pattern::copy_to`]):
//! the row's blades are identical up to that rotation, and so are their neighbourhoods.

use crate::FlankError;
use cam_plan::Row;
use impeller_model::{Blade, BladeSet, Impeller};
use serde::Deserialize;

/// A row as written in job files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RowName {
    /// The main blades.
    Main,
    /// The splitter blades.
    Splitter,
}

impl RowName {
    /// The clearance query's row.
    pub fn row(self) -> Row {
        match self {
            RowName::Main => Row::Main,
            RowName::Splitter => Row::Splitter,
        }
    }
}

/// The default `rows`: both.
pub fn default_rows() -> Vec<RowName> {
    vec![RowName::Main, RowName::Splitter]
}

/// The label of a row in paths, notes and metrics (`main`, `splitter`).
pub fn label(row: Row) -> &'static str {
    match row {
        Row::Main => "main",
        Row::Splitter => "splitter",
    }
}

/// The blade set of `row`; an error when the impeller has no splitters and they are asked
/// for by name.
pub fn blade_set(impeller: &Impeller, row: Row) -> Result<&BladeSet, FlankError> {
    match row {
        Row::Main => Ok(impeller.main()),
        Row::Splitter => impeller.splitter().ok_or_else(|| {
            FlankError::Param("the impeller has no splitter blades (rows = [\"main\"])".into())
        }),
    }
}

/// The rows of `names` this impeller has, in the order given, without repeats. The default
/// (both rows) leaves out the splitters of an impeller without any; a row asked for that the
/// impeller lacks is an error, as is an empty list.
pub fn rows_of(
    impeller: &Impeller,
    names: &[RowName],
    explicit: bool,
) -> Result<Vec<Row>, FlankError> {
    if names.is_empty() {
        return Err(FlankError::Param("rows: at least one row is needed".into()));
    }
    let mut out = Vec::new();
    for n in names {
        let row = n.row();
        if out.contains(&row) {
            continue;
        }
        if row == Row::Splitter && impeller.splitter().is_none() {
            if explicit {
                return Err(FlankError::Param(
                    "rows: the impeller has no splitter blades".into(),
                ));
            }
            continue;
        }
        out.push(row);
    }
    Ok(out)
}

/// Blades that may face a side of the reference blade of `row`: its neighbours in its own
/// row and the nearest instances of the other row (a splitter sits between main blades 0
/// and 1; main blade 0 between splitters n − 1 and 0).
pub fn neighbours(impeller: &Impeller, row: Row) -> Vec<Blade> {
    let main = impeller.main();
    let n = main.count();
    let mut out: Vec<Blade> = Vec::new();
    let mut push = |set: &BladeSet, ks: &[usize], skip_zero: bool| {
        let c = set.count();
        let mut seen = Vec::new();
        for &k in ks {
            let k = k % c.max(1);
            if (skip_zero && k == 0) || seen.contains(&k) {
                continue;
            }
            seen.push(k);
            out.push(set.instance(k));
        }
    };
    match (row, impeller.splitter()) {
        (Row::Main, sp) => {
            push(main, &[1, n.saturating_sub(1)], true);
            if let Some(sp) = sp {
                let m = sp.count();
                push(sp, &[0, m.saturating_sub(1)], false);
            }
        }
        (Row::Splitter, Some(sp)) => {
            let m = sp.count();
            push(sp, &[1, m.saturating_sub(1)], true);
            push(main, &[0, 1], false);
        }
        (Row::Splitter, None) => {}
    }
    out
}

/// Pitch (rad) and count of `row`.
pub fn pitch_and_count(impeller: &Impeller, row: Row) -> Result<(f64, usize), FlankError> {
    let set = blade_set(impeller, row)?;
    Ok((set.pitch_rad(), set.count()))
}
