//! The registry of hysteresis families: **the one list** (`operator_families!`) from which
//! everything that exists once per family is generated.
//!
//! A family is one type in this module's parent that implements [`HysteresisOperator`]
//! (simulate, invert, parameters) and [`OperatorFamily`] (its name, title, validation, values,
//! output scale, held parameters); its identification recipe implements
//! `crate::identify::operators::Identify` in the identify layer (a model never imports an
//! estimator). The list generates:
//!
//! * [`OperatorModel`], the enum of every operator with its serde form
//!   `{"family": "<name>", "operator": {…}}` (the `operator` and `operator_cascade` model files
//!   use it; reading one back goes through the family's validating constructor);
//! * [`Family`], the family names of the command line, the Python package, the model files and
//!   the docs table ([`Family::markdown_table`]), with the Coleman–Hodgdon hysteresis alone
//!   (`ch4`, `ch6`) appended;
//! * in the identify layer, the dispatch of `fit_operator` and of the cascade's start.
//!
//! A new family is its model file, its identification file and one line of
//! `operator_families!` (see `docs/architecture.md`, "Adding a family").

use super::HysteresisOperator;
use crate::{Error, Result};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// What an operator family knows about itself besides simulating and inverting.
pub trait OperatorFamily:
    HysteresisOperator + Clone + PartialEq + Serialize + DeserializeOwned + 'static
{
    /// The family's name on the command line, in model files and in Python (`pi`, `kp`, …).
    const NAME: &'static str;
    /// The model and its reference, one line (the help text and the docs table).
    const TITLE: &'static str;

    /// A small valid operator of the family (registry-wide tests, documentation, the export
    /// checks): an input range of about ±1.
    fn example() -> Result<Self>;

    /// Further small valid operators of the family, one per structure its [`example`] does
    /// not show, each with a short name (a PI with a static envelope: `"envelope"`); the
    /// registry-wide checks and the export checks run them too.
    ///
    /// [`example`]: OperatorFamily::example
    fn variants() -> Result<Vec<(&'static str, Self)>> {
        Ok(Vec::new())
    }

    /// The same operator rebuilt through the family's validating constructor: what a model
    /// file read back must pass (a non-monotone grid, a negative weight, β ≤ 0, … are refused).
    fn checked(self) -> Result<Self>;

    /// The same structure (grids, thresholds, orientation, anhysteretic, …) with the parameter
    /// values `values` in [`HysteresisOperator::parameters`] order, validated. Derived values
    /// (the Maxwell-slip slip forces) are recomputed, not read.
    fn with_values(&self, values: &[f64]) -> Result<Self>;

    /// Indices of the parameters a cascade fit holds fixed besides the family's own fixed
    /// ones (shape exponents the family's own fit holds too; derived values).
    fn held(&self) -> Vec<usize> {
        Vec::new()
    }

    /// Indices of the parameters that scale the output linearly without touching the loop's
    /// shape (Γ → s·Γ when each is multiplied by s > 0); None when the operator has no such
    /// scale (an inverse-parameterised loop, Jiles–Atherton's B(H)).
    fn output_scale(&self) -> Option<Vec<usize>>;
}

/// Checks that `values` holds one finite value per parameter of `op` (the common part of
/// every [`OperatorFamily::with_values`]).
pub fn check_values(op: &dyn HysteresisOperator, values: &[f64]) -> Result<()> {
    let parameters = op.parameters();
    if values.len() != parameters.len() {
        return Err(Error::InvalidModel(format!(
            "a {} operator has {} parameters, got {}",
            op.family(),
            parameters.len(),
            values.len()
        )));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(Error::InvalidParameter {
            name: parameters.get(i).name.clone(),
            value: values[i],
            reason: "must be finite".into(),
        });
    }
    Ok(())
}

/// The one list of operator families: calls `$callback! { Variant: Type, … }` with each
/// family's [`OperatorModel`] variant and its type, in the order of the docs table. Adding a
/// family is adding its line here.
macro_rules! operator_families {
    ($callback:ident) => {
        $callback! {
            Pi: $crate::model::operators::PrandtlIshlinskii,
            Gpi: $crate::model::operators::GeneralizedPi,
            Preisach: $crate::model::operators::Preisach,
            JilesAtherton: $crate::model::operators::JilesAtherton,
            BoucWen: $crate::model::operators::BoucWen,
            Duhem: $crate::model::operators::Duhem,
            Dahl: $crate::model::operators::Dahl,
            MaxwellSlip: $crate::model::operators::MaxwellSlip,
            Backlash: $crate::model::operators::Backlash,
            Kp: $crate::model::operators::Kp,
        }
    };
}
pub(crate) use operator_families;

/// Generates [`OperatorModel`], its unchecked serde mirror and [`Family`] from the list.
macro_rules! define_registry {
    ($($variant:ident: $ty:ty),* $(,)?) => {
        /// A hysteresis operator of any family, serialised as
        /// `{"family": "<name>", "operator": {<the family's structure>}}` and read back through
        /// the family's validating constructor ([`OperatorFamily::checked`]).
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(try_from = "UncheckedOperator", into = "UncheckedOperator")]
        #[allow(missing_docs)] // one variant per family, each named by its type
        pub enum OperatorModel {
            $($variant($ty),)*
        }

        /// The serde form of [`OperatorModel`], before validation.
        #[derive(Clone, Serialize, Deserialize)]
        #[serde(tag = "family", content = "operator", rename_all = "kebab-case")]
        enum UncheckedOperator {
            $($variant($ty),)*
        }

        impl TryFrom<UncheckedOperator> for OperatorModel {
            type Error = Error;
            fn try_from(raw: UncheckedOperator) -> Result<Self> {
                Ok(match raw {
                    $(UncheckedOperator::$variant(m) => Self::$variant(m.checked()?),)*
                })
            }
        }

        impl From<OperatorModel> for UncheckedOperator {
            fn from(model: OperatorModel) -> Self {
                match model {
                    $(OperatorModel::$variant(m) => Self::$variant(m),)*
                }
            }
        }

        $(
            impl From<$ty> for OperatorModel {
                fn from(m: $ty) -> Self {
                    Self::$variant(m)
                }
            }
        )*

        impl OperatorModel {
            /// The operator behind the common trait (simulate, invert, parameters).
            pub fn as_operator(&self) -> &dyn HysteresisOperator {
                match self {
                    $(Self::$variant(m) => m,)*
                }
            }

            /// The family.
            pub fn family(&self) -> Family {
                match self {
                    $(Self::$variant(_) => Family::$variant,)*
                }
            }

            /// See [`OperatorFamily::with_values`].
            pub fn with_values(&self, values: &[f64]) -> Result<Self> {
                check_values(self.as_operator(), values)?;
                Ok(match self {
                    $(Self::$variant(m) => Self::$variant(m.with_values(values)?),)*
                })
            }

            /// See [`OperatorFamily::held`].
            pub fn held(&self) -> Vec<usize> {
                match self {
                    $(Self::$variant(m) => m.held(),)*
                }
            }

            /// [`OperatorFamily::example`] of every family, in the registry's order.
            pub fn examples() -> Result<Vec<Self>> {
                Ok(vec![$(Self::$variant(<$ty as OperatorFamily>::example()?),)*])
            }

            /// [`OperatorFamily::variants`] of every family, in the registry's order.
            pub fn variants() -> Result<Vec<(&'static str, Self)>> {
                let mut out = Vec::new();
                $(out.extend(
                    <$ty as OperatorFamily>::variants()?
                        .into_iter()
                        .map(|(name, m)| (name, Self::$variant(m))),
                );)*
                Ok(out)
            }

            /// See [`OperatorFamily::output_scale`].
            pub fn output_scale(&self) -> Option<Vec<usize>> {
                match self {
                    $(Self::$variant(m) => m.output_scale(),)*
                }
            }
        }

        /// A hysteresis family, named as on the command line: every operator family of
        /// [`OperatorModel`], then the Coleman–Hodgdon hysteresis alone (`ch4`, `ch6`; saved as
        /// kind `coleman_hodgdon`, fitted by `crate::identify::hysteresis`).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[allow(missing_docs)] // each variant is its name (see the docs table)
        pub enum Family {
            $($variant,)*
            Ch4,
            Ch6,
        }

        impl Family {
            /// Every family, in the order of the docs table.
            pub const ALL: &'static [Family] = &[$(Family::$variant,)* Family::Ch4, Family::Ch6];

            /// The family's name (`pi`, `gpi`, …, `ch4`, `ch6`).
            pub fn name(self) -> &'static str {
                match self {
                    $(Family::$variant => <$ty as OperatorFamily>::NAME,)*
                    Family::Ch4 => "ch4",
                    Family::Ch6 => "ch6",
                }
            }

            /// The model and its reference, one line.
            pub fn title(self) -> &'static str {
                match self {
                    $(Family::$variant => <$ty as OperatorFamily>::TITLE,)*
                    Family::Ch4 => CH4_TITLE,
                    Family::Ch6 => CH6_TITLE,
                }
            }

            /// True for the families of [`OperatorModel`] (false for ch4, ch6).
            pub fn is_operator(self) -> bool {
                !matches!(self, Family::Ch4 | Family::Ch6)
            }
        }
    };
}

operator_families!(define_registry);

const CH4_TITLE: &str =
    "Coleman–Hodgdon hysteresis alone, 4 parameters (Coleman & Hodgdon 1986; Vörös 2015)";
const CH6_TITLE: &str =
    "Coleman–Hodgdon hysteresis alone, 6 parameters (Coleman & Hodgdon 1986; Vörös 2015)";

impl Family {
    /// Every family's name, in [`Family::ALL`] order.
    pub fn names() -> Vec<&'static str> {
        Family::ALL.iter().map(|f| f.name()).collect()
    }

    /// The operator families (every family but ch4, ch6), in [`Family::ALL`] order.
    pub fn operators() -> impl Iterator<Item = Family> {
        Family::ALL.iter().copied().filter(|f| f.is_operator())
    }

    /// The family named `name` (case-insensitive; `_` for `-` accepted).
    pub fn parse(name: &str) -> Result<Family> {
        let wanted = name.trim().to_ascii_lowercase().replace('_', "-");
        Family::ALL
            .iter()
            .copied()
            .find(|f| f.name() == wanted)
            .ok_or_else(|| {
                Error::invalid_option(
                    "family",
                    name,
                    format!(
                        "unknown hysteresis family '{name}'; use one of {}",
                        Family::names().join(", ")
                    ),
                )
            })
    }

    /// The operator family named `name` (not ch4/ch6): what a cascade's operator or a model
    /// file's `family` may be.
    pub fn parse_operator(name: &str) -> Result<Family> {
        let family = Family::parse(name)?;
        if family.is_operator() {
            return Ok(family);
        }
        let operators: Vec<&str> = Family::operators().map(Family::name).collect();
        Err(Error::invalid_option(
            "family",
            name,
            format!(
                "'{name}' is not an operator family; use one of {}",
                operators.join(", ")
            ),
        ))
    }

    /// A comma-separated list of families, or `all`; duplicates dropped, order kept.
    pub fn parse_list(list: &str) -> Result<Vec<Family>> {
        if list.trim().eq_ignore_ascii_case("all") {
            return Ok(Family::ALL.to_vec());
        }
        let mut out: Vec<Family> = Vec::new();
        for name in list.split(',').filter(|s| !s.trim().is_empty()) {
            let f = Family::parse(name).map_err(|e| match e {
                Error::InvalidOption { value, reason, .. } => Error::InvalidOption {
                    option: "families".into(),
                    value,
                    reason,
                },
                other => other,
            })?;
            if !out.contains(&f) {
                out.push(f);
            }
        }
        if out.is_empty() {
            return Err(Error::invalid_option(
                "families",
                "[]",
                "the family list is empty; name at least one family, or all".into(),
            ));
        }
        Ok(out)
    }

    /// The docs table of the families (`| name | model |` rows), as `docs/zoo.md` holds it.
    pub fn markdown_table() -> String {
        let mut table = String::from("| family | model (reference) |\n|---|---|\n");
        for f in Family::ALL {
            table.push_str(&format!("| `{}` | {} |\n", f.name(), f.title()));
        }
        table
    }
}

impl std::fmt::Display for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl OperatorModel {
    /// The operator of family `family` from its structure (the family's serde form), checked
    /// by the family's constructor.
    pub fn from_structure(family: &str, structure: &serde_json::Value) -> Result<Self> {
        let family = Family::parse_operator(family)?;
        let tagged = serde_json::json!({"family": family.name(), "operator": structure});
        serde_json::from_value(tagged).map_err(|e| {
            Error::InvalidModel(format!(
                "the \"operator\" object is not a valid {family} operator ({e}); save the model again"
            ))
        })
    }

    /// The full structure as a JSON object (the operator's serde form without the family tag).
    pub fn structure(&self) -> Result<serde_json::Value> {
        let mut tagged = serde_json::to_value(self)
            .map_err(|e| Error::Serialization(format!("operator structure: {e}")))?;
        tagged
            .get_mut("operator")
            .map(serde_json::Value::take)
            .ok_or_else(|| Error::Serialization("operator structure: no \"operator\" key".into()))
    }

    /// The operator whose output is s·Γ\[u\] (s > 0, finite), where the family has an output
    /// scale ([`OperatorFamily::output_scale`]); None otherwise.
    pub fn scaled(&self, s: f64) -> Option<Self> {
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        let mut values = self.as_operator().parameters().values();
        for i in self.output_scale()? {
            values[i] *= s;
        }
        self.with_values(&values).ok()
    }
}

/// The values of a family with a fixed parameter count, checked by [`check_values`] (for
/// destructuring by name in [`OperatorFamily::with_values`]).
pub fn values_array<const N: usize>(
    op: &dyn HysteresisOperator,
    values: &[f64],
) -> Result<[f64; N]> {
    check_values(op, values)?;
    values.try_into().map_err(|_| {
        Error::InvalidModel(format!(
            "a {} operator has {N} parameters, got {}",
            op.family(),
            values.len()
        ))
    })
}
