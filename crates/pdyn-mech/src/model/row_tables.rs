//! `[tables.NAME]`: node and element tables (a CAD or FE tool's export, a DataFrame saved as
//! CSV) that families run over, one member per row.
//!
//! ```toml
//! [tables.nodes]
//! file = "truss_nodes.csv"   # columns id, x, y, fixed: CSV or Parquet, told by its bytes
//! key = "id"                 # rows are named by their id (else by their 0-based number)
//!
//! [particles."N[r]"]
//! for = "r in nodes"         # r runs over the ids; nodes_x is the row's x
//! where = "nodes_fixed == 0"
//! position = "[X[r], Y[r], 0]"
//! ```
//!
//! The file is read with `pdyn_data::source` as `[data.NAME]` files are (every value a finite
//! number, problems located by file, line and column). Column `c` of table `T` is the name
//! `T_c`, as a `[data.NAME]` column is the function `NAME_c`: in a member of a family over
//! `T` it is that row's value (an integer one may index: `N[bars_a]`), elsewhere `T_c[k]` is
//! the value at the row named `k`. `T` alone is the number of rows, a size like those of
//! `[indices]`.

use super::data::{data_path, is_function_name, located};
use super::families::MAX_MEMBERS;
use super::raw::{Name, RawModel, RawTable};
use super::{Loader, ModelError};
use pdyn_data::csv::Columns;
use pdyn_data::source::Source;
use pdyn_expr::lower::Binding;
use pdyn_expr::Value;
use rustc_hash::FxHashMap;
use toml::Spanned;

/// Integers beyond this are not all exact in an `f64`: a cell this large is no index.
const EXACT_INTEGERS: f64 = 9_007_199_254_740_992.0;

/// One `[tables.NAME]`, read.
#[derive(Debug)]
pub(crate) struct RowTable {
    /// The table's name (`nodes`).
    pub name: String,
    /// The file as shown in messages.
    pub file: String,
    /// The columns, with the line of each row and the place of each cell.
    columns: Columns,
    /// The key column, if declared: its index in `columns` and its name.
    key: Option<(usize, String)>,
    /// Each row's name: its key, or its 0-based number.
    pub keys: Vec<i64>,
    /// The row of each key (a keyed table).
    row_of_key: FxHashMap<i64, usize>,
}

impl RowTable {
    /// The number of rows.
    pub fn len(&self) -> usize {
        self.columns.len()
    }

    /// The row named `key`.
    pub fn row_of(&self, key: i64) -> Option<usize> {
        match self.key {
            Some(_) => self.row_of_key.get(&key).copied(),
            None => usize::try_from(key).ok().filter(|&r| r < self.len()),
        }
    }

    /// The index of column `name`.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.columns.names.iter().position(|n| n == name)
    }

    /// The columns' names.
    pub fn column_names(&self) -> &[String] {
        &self.columns.names
    }

    /// The value in `row` of column `col`.
    pub fn value(&self, row: usize, col: usize) -> f64 {
        self.columns.values[col][row]
    }

    /// The 1-based line of `row` in its file (its number, for a Parquet file).
    pub fn line(&self, row: usize) -> usize {
        self.columns.lines.get(row).copied().unwrap_or(0)
    }

    /// `message` about the cell at `row`, `col`, as `file:line:column: message (column `c`,
    /// text `t`)`.
    pub fn cell_message(&self, row: usize, col: usize, message: impl Into<String>) -> String {
        located(&self.columns.error_at(row, col, message))
    }

    /// The value at `row`, `col` as an index: an integer, or why it is not one.
    pub fn integer(&self, row: usize, col: usize, name: &str) -> Result<i64, String> {
        let x = self.value(row, col);
        if x.fract() == 0.0 && x.abs() < EXACT_INTEGERS {
            return Ok(x as i64);
        }
        Err(self.cell_message(
            row,
            col,
            format!("`{name}` is used as an index, but {x} is not an integer"),
        ))
    }

    /// How its rows are named, for messages: `the ids in column `id``, `rows 0..=24`.
    pub fn naming(&self) -> String {
        match &self.key {
            Some((_, k)) => format!("the values of its key column `{k}`"),
            None => format!("its row numbers 0..{}", self.len().saturating_sub(1)),
        }
    }
}

impl Loader<'_> {
    /// `[tables.NAME]`: each file read, its size `NAME` and its columns `NAME_c` declared.
    pub(super) fn read_row_tables(&mut self, raw: &RawModel) -> Result<Vec<RowTable>, ModelError> {
        let mut out = Vec::with_capacity(raw.tables.len());
        let mut members = 0usize;
        for (name, table) in &raw.tables {
            let t = self.read_row_table(name, table)?;
            members = members.saturating_add(t.len());
            if members as u64 > MAX_MEMBERS {
                return Err(self
                    .err(
                        name.span(),
                        format!(
                            "the tables have {members} rows together, more than the {MAX_MEMBERS} members a model's families may have"
                        ),
                    )
                    .help("a model of this size cannot be loaded"));
            }
            let rows = i64::try_from(t.len()).unwrap_or(i64::MAX);
            let size = Value::Scalar(self.pool.int(rows));
            self.declare(name.get_ref(), name.span(), "table", Binding::Value(size))?;
            self.dims
                .bind(name.get_ref(), pdyn_expr::Dimension::NONE.into());
            for column in t.column_names() {
                let full = format!("{}_{column}", name.get_ref());
                if !is_function_name(&full) {
                    return Err(self
                        .err(name.span(), format!("the column `{column}` of {} gives the name `{full}`, which is not a name", t.file))
                        .help("column names are letters, digits and `_` (rename the column in the file's header, or choose columns with `columns = [...]`)"));
                }
                // A placeholder: the scope gives a column's value per member (never this).
                let placeholder = Value::Scalar(self.pool.int(0));
                self.declare(
                    &full,
                    name.span(),
                    "table column",
                    Binding::Value(placeholder),
                )?;
                let form = self.dims.fresh(&full);
                self.dims.bind(&full, form);
            }
            out.push(t);
        }
        Ok(out)
    }

    fn read_row_table(
        &mut self,
        name: &Name,
        table: &Spanned<RawTable>,
    ) -> Result<RowTable, ModelError> {
        let t = table.get_ref();
        let Some(file) = &t.file else {
            return Err(self
                .err(name.span(), format!("[tables.{}] needs `file`", name.get_ref()))
                .help("file = \"nodes.csv\": a CSV file with a header line (or a Parquet file), relative to the model file"));
        };
        let path = data_path(self.origin, file.get_ref());
        let shown = path.display().to_string();
        let bytes = std::fs::read(&path).map_err(|e| {
            self.err(
                file.span(),
                format!(
                    "cannot read the table file {shown} of [tables.{}]: {e}",
                    name.get_ref()
                ),
            )
            .help("the path is relative to the model file's directory")
        })?;
        let table_error = |ld: &Loader, e: pdyn_data::DataError| {
            let err = ld.err(
                file.span(),
                format!("table `{}`: {}", name.get_ref(), located(&e)),
            );
            match e.help {
                Some(h) if e.message.starts_with("no column named") => err.help(format!(
                    "{h}; a table reads every column unless `columns = [...]` names them"
                )),
                Some(h) => err.help(h),
                None => err,
            }
        };
        let source = Source::from_bytes(&shown, bytes).map_err(|e| table_error(self, e))?;
        let mut wanted: Vec<&str> = Vec::new();
        if let Some(cols) = &t.columns {
            wanted.extend(cols.get_ref().iter().map(|c| c.get_ref().as_str()));
            if let Some(k) = &t.key {
                if !wanted.contains(&k.get_ref().as_str()) {
                    wanted.push(k.get_ref());
                }
            }
        }
        let columns = source
            .read_columns(&shown, &wanted)
            .map_err(|e| table_error(self, e))?;
        if columns.is_empty() {
            return Err(self
                .err(
                    file.span(),
                    format!("table `{}`: {shown} has no rows", name.get_ref()),
                )
                .help("a table needs one row per member below its header"));
        }
        let mut out = RowTable {
            name: name.get_ref().clone(),
            file: shown,
            columns,
            key: None,
            keys: Vec::new(),
            row_of_key: FxHashMap::default(),
        };
        match &t.key {
            None => out.keys = (0..out.len() as i64).collect(),
            Some(k) => {
                let Some(col) = out.column(k.get_ref()) else {
                    return Err(self
                        .err(
                            k.span(),
                            format!(
                                "table `{}` has no column `{}` to be its key",
                                name.get_ref(),
                                k.get_ref()
                            ),
                        )
                        .help(format!(
                            "its columns are {}",
                            quoted_list(out.column_names())
                        )));
                };
                let key_name = format!("{}_{}", name.get_ref(), k.get_ref());
                out.keys.reserve(out.len());
                out.row_of_key.reserve(out.len());
                for row in 0..out.len() {
                    let key = out.integer(row, col, &key_name).map_err(|m| {
                        self.err(k.span(), format!("table `{}`: {m}", name.get_ref()))
                            .help("a key names its row: an integer (a node number)")
                    })?;
                    if let Some(&first) = out.row_of_key.get(&key) {
                        let m = out.cell_message(
                            row,
                            col,
                            format!(
                                "the key {key} appears twice (first at line {})",
                                out.line(first)
                            ),
                        );
                        return Err(self
                            .err(k.span(), format!("table `{}`: {m}", name.get_ref()))
                            .help("every row of a keyed table needs its own key"));
                    }
                    out.row_of_key.insert(key, row);
                    out.keys.push(key);
                }
                out.key = Some((col, k.get_ref().clone()));
            }
        }
        Ok(out)
    }
}

/// `` `a`, `b`, `c` ``.
pub(crate) fn quoted_list(names: &[String]) -> String {
    names
        .iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}
