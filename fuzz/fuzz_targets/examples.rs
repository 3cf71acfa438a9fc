//! The shipped examples, shared by the structure-aware targets: a fuzz input picks an example
//! and one of its TOML values, and replaces that value with the rest of the input. This keeps
//! every mutated model one edit away from a valid one, so the fuzzer spends its time deep in
//! loading, deriving, solving and running rather than in the TOML parser.

pub const EXAMPLES: &[(&str, &str)] = &[
    ("aircraft_turn", include_str!("../../examples/aircraft_turn.toml")),
    ("bicycle", include_str!("../../examples/bicycle.toml")),
    ("building", include_str!("../../examples/building.toml")),
    ("kremlin_stone", include_str!("../../examples/kremlin_stone.toml")),
    ("nanoparticle", include_str!("../../examples/nanoparticle.toml")),
    ("pendulum_chain_2", include_str!("../../examples/pendulum_chain_2.toml")),
    ("pendulum_chain_3", include_str!("../../examples/pendulum_chain_3.toml")),
    ("projectile_drag", include_str!("../../examples/projectile_drag.toml")),
    ("pulley", include_str!("../../examples/pulley.toml")),
    ("rotating_bar_block", include_str!("../../examples/rotating_bar_block.toml")),
    ("rotating_rod_block", include_str!("../../examples/rotating_rod_block.toml")),
    ("satellite", include_str!("../../examples/satellite.toml")),
    ("satellite_ode45", include_str!("../../examples/satellite_ode45.toml")),
    ("suspension", include_str!("../../examples/suspension.toml")),
    ("tablecloth", include_str!("../../examples/tablecloth.toml")),
    ("takeoff", include_str!("../../examples/takeoff.toml")),
    ("window_blind", include_str!("../../examples/window_blind.toml")),
];

#[path = "../../crates/pdyn/tests/common/toml_values.rs"]
mod toml_values;
use toml_values::value_spans;

/// `(example name, mutated text)`: byte 0 picks the example, byte 1 the value, the rest
/// (UTF-8) replaces it. `None` for inputs too short or not UTF-8.
pub fn mutate(data: &[u8]) -> Option<(&'static str, String)> {
    if data.len() < 2 {
        return None;
    }
    let (name, src) = EXAMPLES[data[0] as usize % EXAMPLES.len()];
    let spans = value_spans(src);
    let (s, e) = spans[data[1] as usize % spans.len()];
    let replacement = std::str::from_utf8(&data[2..]).ok()?;
    if replacement.len() > 4096 {
        return None;
    }
    Some((name, format!("{}{}{}", &src[..s], replacement, &src[e..])))
}
