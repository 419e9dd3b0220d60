//! An operation's own metrics (a typed map under the fixed names of DESIGN §4) and the data
//! of its plots (rendered by the pipeline's report).

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One metric value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum MetricValue {
    /// A true/false figure (`alpha_monotone`).
    Bool(bool),
    /// A count (`interference_positions_after`, `slp_iterations`).
    Count(u64),
    /// A measured number with its unit in the name (`hub_allowance_max_mm`).
    Number(f64),
    /// A stated reason (`slp_termination`).
    Text(String),
}

impl MetricValue {
    /// The value as a number (booleans as 0/1), `None` for text.
    pub fn as_f64(&self) -> Option<f64> {
        match *self {
            MetricValue::Bool(b) => Some(if b { 1.0 } else { 0.0 }),
            MetricValue::Count(c) => Some(c as f64),
            MetricValue::Number(x) => Some(x),
            MetricValue::Text(_) => None,
        }
    }
}

/// Metrics by name (snake_case, unit suffix), kept in name order.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Metrics(pub BTreeMap<String, MetricValue>);

impl Metrics {
    /// An empty map.
    pub fn new() -> Self {
        Self::default()
    }
    /// Sets a number.
    pub fn number(&mut self, name: &str, value: f64) -> &mut Self {
        self.0.insert(name.into(), MetricValue::Number(value));
        self
    }
    /// Sets a count.
    pub fn count(&mut self, name: &str, value: usize) -> &mut Self {
        self.0.insert(name.into(), MetricValue::Count(value as u64));
        self
    }
    /// Sets a boolean.
    pub fn flag(&mut self, name: &str, value: bool) -> &mut Self {
        self.0.insert(name.into(), MetricValue::Bool(value));
        self
    }
    /// Sets a text.
    pub fn text(&mut self, name: &str, value: impl Into<String>) -> &mut Self {
        self.0.insert(name.into(), MetricValue::Text(value.into()));
        self
    }
    /// The value of `name`.
    pub fn get(&self, name: &str) -> Option<&MetricValue> {
        self.0.get(name)
    }
}

/// One named series of (x, y) points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlotSeries {
    /// Legend label.
    pub label: String,
    /// Points in order.
    pub points: Vec<[f64; 2]>,
}

/// What a plot shows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum PlotKind {
    /// Line chart of one or more series.
    Lines {
        /// Label of the x axis (with unit).
        x_label: String,
        /// Label of the y axis (with unit).
        y_label: String,
        /// The series.
        series: Vec<PlotSeries>,
        /// Draw with equal scales on both axes (geometry in mm).
        equal_aspect: bool,
    },
    /// A map of values over a grid (rows = second parameter), `NaN` where there is none.
    HeatMap {
        /// Rows of values.
        values: Vec<Vec<f64>>,
        /// Unit of the values.
        unit: String,
    },
}

/// One plot of an operation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plot {
    /// Title shown above the plot.
    pub title: String,
    /// Its data.
    pub kind: PlotKind,
}
