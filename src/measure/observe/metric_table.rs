//! The metrics table: every accuracy and quality number of a run that a document shows,
//! declared once with everywhere it appears: its `compare.csv` column (the [`Metrics`] field's
//! name), its key in the report's method rows (`summary.json` and the pages read these), and
//! its column in a scene page's methods table. A new metric is its field and computation in
//! `metrics.rs` plus one entry here.

use crate::measure::metrics::Metrics;
use serde::de::{Deserialize, Deserializer, IgnoredAny, MapAccess, Visitor};
use serde::ser::{Serialize, SerializeMap, Serializer};

/// One value of a metric.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value {
    /// A number, written `{:e}` in `compare.csv`.
    Number(f64),
    /// A yes/no finding, written `true`/`false`.
    Flag(bool),
}

/// How a page cell shows a metric's number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PageFormat {
    /// With this many significant digits.
    Significant(usize),
    /// As a percentage with this many significant digits (a relative energy error).
    Percent(usize),
}

/// A metric's column in a scene page's methods table.
#[derive(Debug, Clone, Copy)]
pub struct PageColumn {
    /// The header as people read it.
    pub header: &'static str,
    /// Shown in the Markdown overview too (the page shows every column).
    pub in_markdown: bool,
    /// How its cells show the number.
    pub format: PageFormat,
}

/// One metric of the table.
#[derive(Debug, Clone, Copy)]
pub struct Metric {
    /// Its `compare.csv` column: the [`Metrics`] field's name.
    pub key: &'static str,
    /// Its value in a run's metrics, absent where the run does not have it.
    pub value: fn(&Metrics) -> Option<Value>,
    /// Its key in the report's method rows, where the report carries it.
    pub row_key: Option<&'static str>,
    /// Its column in a scene page's methods table, where the page shows it.
    pub page: Option<PageColumn>,
}

/// A metric holding a number field of [`Metrics`] (`field?` for an optional one), in no
/// report row and on no page.
macro_rules! number {
    ($key:ident) => {
        Metric {
            key: stringify!($key),
            value: |m| Some(Value::Number(m.$key)),
            row_key: None,
            page: None,
        }
    };
    ($key:ident?) => {
        Metric {
            key: stringify!($key),
            value: |m| m.$key.map(Value::Number),
            row_key: None,
            page: None,
        }
    };
}

/// The row key of the largest position error over the run (m).
pub const MAX_POSITION_ERROR: &str = "max_position_error";
/// The row key of the largest |relative energy error|.
pub const MAX_ENERGY_DRIFT: &str = "max_energy_drift";
/// The row key of the deepest penetration into any obstacle (m).
pub const PENETRATION_MAX: &str = "penetration_max";

/// Every metric, in `compare.csv`'s order, which is also the page's order of their columns.
pub const METRICS: [Metric; 21] = [
    Metric {
        row_key: Some("final_position_error"),
        ..number!(error_final)
    },
    Metric {
        row_key: Some(MAX_POSITION_ERROR),
        page: Some(PageColumn {
            header: "max position error (m)",
            in_markdown: true,
            format: PageFormat::Significant(2),
        }),
        ..number!(error_max)
    },
    number!(error_rms),
    number!(energy_drift),
    Metric {
        row_key: Some("energy_drift_rate"),
        page: Some(PageColumn {
            header: "energy drift rate (J/s)",
            in_markdown: false,
            format: PageFormat::Significant(2),
        }),
        ..number!(energy_drift_rate)
    },
    number!(energy_oscillation),
    Metric {
        row_key: Some(MAX_ENERGY_DRIFT),
        page: Some(PageColumn {
            header: "max energy error",
            in_markdown: true,
            format: PageFormat::Percent(2),
        }),
        ..number!(energy_error_max)
    },
    Metric {
        row_key: Some("final_energy_change"),
        page: Some(PageColumn {
            header: "final energy change",
            in_markdown: false,
            format: PageFormat::Percent(2),
        }),
        ..number!(energy_balance)
    },
    number!(momentum_drift?),
    number!(constraint_max?),
    number!(constraint_mean?),
    Metric {
        row_key: Some("strain_max"),
        page: Some(PageColumn {
            header: "strain max",
            in_markdown: true,
            format: PageFormat::Significant(2),
        }),
        ..number!(strain_max)
    },
    Metric {
        row_key: Some(PENETRATION_MAX),
        ..number!(penetration_max?)
    },
    Metric {
        row_key: Some("rest_jitter"),
        ..number!(rest_jitter)
    },
    number!(period?),
    number!(period_error?),
    number!(phase_error?),
    number!(error_max_predictable),
    number!(strain_error),
    Metric {
        key: "statistics_score",
        value: |m| {
            m.statistics
                .as_ref()
                .map(|s| Value::Number(crate::measure::statistics::worst_score(s)))
        },
        row_key: None,
        page: None,
    },
    Metric {
        key: "statistics_consistent",
        value: |m| {
            m.statistics
                .as_ref()
                .map(|s| Value::Flag(s.values().all(|v| v.consistent)))
        },
        row_key: None,
        page: None,
    },
];

/// The metrics' `compare.csv` columns, comma-separated, in order.
pub fn csv_header() -> String {
    let keys: Vec<&str> = METRICS.iter().map(|c| c.key).collect();
    keys.join(",")
}

/// The metrics' `compare.csv` cells of one run, in [`METRICS`]' order; all empty for a run
/// that is not ok (`None`).
pub fn csv_cells(m: Option<&Metrics>) -> Vec<String> {
    METRICS
        .iter()
        .map(|c| match m.and_then(|m| (c.value)(m)) {
            Some(Value::Number(x)) => format!("{x:e}"),
            Some(Value::Flag(b)) => b.to_string(),
            None => String::new(),
        })
        .collect()
}

/// A run's values of the metrics that have a row key, in [`METRICS`]' order: finite numbers
/// only (a non-finite or missing one is null). Written into a method row as its own keys.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RowMetrics(Vec<(&'static str, Option<f64>)>);

impl RowMetrics {
    /// The row values of a run's metrics (every one null for a run that is not ok, `None`).
    pub fn of(m: Option<&Metrics>) -> Self {
        RowMetrics(
            METRICS
                .iter()
                .filter_map(|c| {
                    let key = c.row_key?;
                    let value = match m.and_then(|m| (c.value)(m)) {
                        Some(Value::Number(x)) if x.is_finite() => Some(x),
                        _ => None,
                    };
                    Some((key, value))
                })
                .collect(),
        )
    }

    /// The value under the row key `key` (one of [`METRICS`]' row keys), if the run has it.
    pub fn get(&self, key: &str) -> Option<f64> {
        self.0.iter().find(|(k, _)| *k == key).and_then(|(_, v)| *v)
    }
}

impl Serialize for RowMetrics {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            map.serialize_entry(k, v)?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for RowMetrics {
    /// Reads the row keys of [`METRICS`] from a map (a method row's own keys, flattened),
    /// ignoring every other key; a row key that is missing reads as null.
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Keys;
        impl<'de> Visitor<'de> for Keys {
            type Value = RowMetrics;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a method row's metrics")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<RowMetrics, A::Error> {
                let mut row = RowMetrics::of(None);
                while let Some(key) = map.next_key::<String>()? {
                    match row.0.iter_mut().find(|(k, _)| *k == key) {
                        Some(slot) => slot.1 = map.next_value::<Option<f64>>()?,
                        None => {
                            map.next_value::<IgnoredAny>()?;
                        }
                    }
                }
                Ok(row)
            }
        }
        d.deserialize_map(Keys)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: the JSON form of a run's metrics (serde's own field names). Every metric's
    /// column is a field of [`Metrics`] by that name, or a statistics summary; no two metrics
    /// share a column, and no two share a row key; a metric on the page has a row key.
    #[test]
    fn every_column_is_a_metrics_field_and_keys_are_unique() {
        let m = Metrics {
            period: Some(1.0),
            momentum_drift: Some(0.0),
            ..Metrics::default()
        };
        let json = serde_json::to_value(&m).unwrap();
        for c in &METRICS {
            if !c.key.starts_with("statistics_") {
                assert!(json.get(c.key).is_some(), "{} is no Metrics field", c.key);
            }
        }
        let unique = |mut keys: Vec<&str>| {
            let n = keys.len();
            keys.sort_unstable();
            keys.dedup();
            keys.len() == n
        };
        assert!(unique(METRICS.iter().map(|c| c.key).collect()));
        assert!(unique(METRICS.iter().filter_map(|c| c.row_key).collect()));
        // The page reads its cells from the method rows: a page column needs a row key.
        for c in &METRICS {
            assert!(
                c.page.is_none() || c.row_key.is_some(),
                "{} has no row key",
                c.key
            );
        }
    }

    /// A row's values survive the JSON round trip beside other keys, non-finite ones as null;
    /// a run that is not ok has every value null.
    #[test]
    fn row_metrics_round_trip_and_drop_non_finite() {
        let m = Metrics {
            error_max: 0.25,
            energy_error_max: f64::NAN,
            penetration_max: Some(1e-3),
            ..Metrics::default()
        };
        let row = RowMetrics::of(Some(&m));
        assert_eq!(row.get(MAX_POSITION_ERROR), Some(0.25));
        assert_eq!(row.get(MAX_ENERGY_DRIFT), None);
        assert_eq!(row.get(PENETRATION_MAX), Some(1e-3));
        let mut json = serde_json::to_value(&row).unwrap();
        json["method"] = "x".into();
        let back: RowMetrics = serde_json::from_value(json).unwrap();
        assert_eq!(back, row);
        assert!(RowMetrics::of(None).0.iter().all(|(_, v)| v.is_none()));
    }
}
