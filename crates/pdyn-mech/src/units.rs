//! Unit literals in model files (`"25 mph"`, `"45 deg"`, `"100 N/m"`): the table, the
//! grammar and the dimensions live in [`pdyn_expr::units`], beside the expression parser that
//! also reads them inside expressions (`2*pi/(120 s)`).

pub use pdyn_expr::units::*;
