//! Named model parameters with unit, bounds and a fixed flag (MATLAB `idnlgrey` vocabulary).

use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// One model parameter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Parameter {
    /// Name: the literature's symbol (`alpha`, `m1`, `a1`, `J`, …).
    pub name: String,
    /// Unit ("" when dimensionless or unknown).
    pub unit: String,
    /// Current (initial or estimated) value.
    pub value: f64,
    /// Lower bound (may be −∞).
    pub min: f64,
    /// Upper bound (may be +∞).
    pub max: f64,
    /// When true the estimator keeps the value.
    pub fixed: bool,
}

impl Parameter {
    /// A free, unbounded parameter.
    pub fn new(name: impl Into<String>, value: f64) -> Self {
        Self {
            name: name.into(),
            unit: String::new(),
            value,
            min: f64::NEG_INFINITY,
            max: f64::INFINITY,
            fixed: false,
        }
    }

    /// Sets the unit.
    pub fn unit(mut self, unit: impl Into<String>) -> Self {
        self.unit = unit.into();
        self
    }

    /// Sets the bounds.
    pub fn bounds(mut self, min: f64, max: f64) -> Self {
        self.min = min;
        self.max = max;
        self
    }

    /// Sets the fixed flag.
    pub fn fixed(mut self, fixed: bool) -> Self {
        self.fixed = fixed;
        self
    }
}

/// An ordered set of named parameters.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ParameterSet {
    params: Vec<Parameter>,
}

impl ParameterSet {
    /// A set from a list; names must be unique.
    pub fn new(params: Vec<Parameter>) -> Result<Self> {
        for (i, p) in params.iter().enumerate() {
            if params[..i].iter().any(|q| q.name == p.name) {
                return Err(Error::InvalidModel(format!(
                    "parameter name '{}' appears twice",
                    p.name
                )));
            }
        }
        Ok(Self { params })
    }

    /// The first `n` parameters (all when there are fewer).
    pub fn leading(&self, n: usize) -> Self {
        Self {
            params: self.params.iter().take(n).cloned().collect(),
        }
    }

    /// Free parameters named `names` with values `values`, unbounded.
    pub fn from_values(names: &[String], values: &[f64]) -> Result<Self> {
        Self::new(
            names
                .iter()
                .zip(values)
                .map(|(n, &v)| Parameter::new(n.clone(), v))
                .collect(),
        )
    }

    /// Number of parameters (fixed included).
    pub fn len(&self) -> usize {
        self.params.len()
    }

    /// True when there are no parameters.
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// All parameters.
    pub fn iter(&self) -> impl Iterator<Item = &Parameter> {
        self.params.iter()
    }

    /// The parameter at index `i`.
    pub fn get(&self, i: usize) -> &Parameter {
        &self.params[i]
    }

    /// Mutable access to the parameter at index `i`.
    pub fn get_mut(&mut self, i: usize) -> &mut Parameter {
        &mut self.params[i]
    }

    /// Index of the parameter called `name`.
    pub fn index_of(&self, name: &str) -> Result<usize> {
        self.params
            .iter()
            .position(|p| p.name == name)
            .ok_or_else(|| {
                Error::UnknownParameter(format!(
                    "no parameter named '{name}' (parameters: {})",
                    self.names().join(", ")
                ))
            })
    }

    /// Mutable access by name.
    pub fn by_name_mut(&mut self, name: &str) -> Result<&mut Parameter> {
        let i = self.index_of(name)?;
        Ok(&mut self.params[i])
    }

    /// The names in order.
    pub fn names(&self) -> Vec<String> {
        self.params.iter().map(|p| p.name.clone()).collect()
    }

    /// The values in order.
    pub fn values(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.value).collect()
    }

    /// Sets all values (length must match).
    pub fn set_values(&mut self, values: &[f64]) {
        for (p, &v) in self.params.iter_mut().zip(values) {
            p.value = v;
        }
    }

    /// Indices of the free parameters.
    pub fn free_indices(&self) -> Vec<usize> {
        (0..self.params.len())
            .filter(|&i| !self.params[i].fixed)
            .collect()
    }

    /// Checks every value is finite and inside its bounds, and every min < max.
    pub fn validate(&self) -> Result<()> {
        for p in &self.params {
            if !p.value.is_finite() {
                return Err(Error::InvalidParameter {
                    name: p.name.clone(),
                    value: p.value,
                    reason: "initial value must be finite".into(),
                });
            }
            if p.min.is_nan() || p.max.is_nan() || p.min >= p.max {
                return Err(Error::InvalidParameter {
                    name: p.name.clone(),
                    value: p.value,
                    reason: format!("bounds [{}, {}] are empty; need min < max", p.min, p.max),
                });
            }
            if p.value < p.min || p.value > p.max {
                return Err(Error::InvalidParameter {
                    name: p.name.clone(),
                    value: p.value,
                    reason: format!(
                        "initial value outside its bounds [{}, {}]; move it inside or widen the bounds",
                        crate::error::number(&p.min),
                        crate::error::number(&p.max)
                    ),
                });
            }
        }
        Ok(())
    }
}
