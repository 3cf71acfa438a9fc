//! Initial conditions written in `[unknowns]`: a conical pendulum's `rate = "omega"` where
//! `omega` is what `pdyn forces` solves for.
//!
//! Such a model describes a motion that is *prescribed up to unknowns*: `pdyn forces`
//! substitutes the expression (the unknown itself) for the coordinate's rate and solves for it
//! with the forces, so the model is valid. A run, a sweep or a check integrates from numbers,
//! and there the expression has none: [`Model::unknown_initial_error`] is the located refusal
//! they give instead of a NaN initial state.

use super::{Model, ModelError};
use std::ops::Range;

/// A coordinate's `initial` or `rate` that names one or more `[unknowns]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownInitial {
    /// Index of the coordinate in [`Model::coordinates`].
    pub coordinate: usize,
    /// Its name.
    pub name: String,
    /// `"initial"` or `"rate"`.
    pub key: &'static str,
    /// The expression as written (`omega`).
    pub text: String,
    /// The unknowns it names, in `[unknowns]` order.
    pub unknowns: Vec<String>,
    /// The coordinate's table in the file (its values carry no spans of their own).
    pub span: Range<usize>,
}

impl UnknownInitial {
    /// `the unknown `omega`` / `the unknowns `a`, `b``.
    fn unknowns_text(&self) -> String {
        let quoted: Vec<String> = self.unknowns.iter().map(|u| format!("`{u}`")).collect();
        if quoted.len() == 1 {
            format!("the unknown {}", quoted[0])
        } else {
            format!("the unknowns {}", quoted.join(", "))
        }
    }
}

impl Model {
    /// The located error of a command that needs numeric initial conditions (`run`, `sweep`,
    /// `check`) on a model whose initial value or rate is an unknown of `pdyn forces`; `None`
    /// when every initial condition is a number.
    pub fn unknown_initial_error(&self) -> Option<ModelError> {
        let u = self.unknown_initials.first()?;
        let what = if u.key == "rate" {
            "rate"
        } else {
            "initial value"
        };
        Some(
            ModelError::new(
                &self.origin,
                u.span.clone(),
                format!(
                    "the {what} of `{}` (`{} = \"{}\"`) names {}, which `pdyn forces` solves \
                     for: a run needs a number here",
                    u.name,
                    u.key,
                    u.text,
                    u.unknowns_text(),
                ),
            )
            .help(format!(
                "find {} with `pdyn forces {}`; to run the motion, move {} from [unknowns] to \
                 [parameters] with that value",
                u.unknowns.join(", "),
                self.origin,
                if u.unknowns.len() == 1 { "it" } else { "them" }
            )),
        )
    }

    /// The `initial` or `rate` of coordinate `index` that names an unknown, if any.
    pub fn unknown_initial(&self, index: usize, key: &str) -> Option<&UnknownInitial> {
        self.unknown_initials
            .iter()
            .find(|u| u.coordinate == index && u.key == key)
    }
}
