//! Initial conditions shared by the integration tests (see `pdyn_gravity::systems`).
#![allow(dead_code, unused_imports)]

pub use pdyn_gravity::systems::{
    figure_eight, figure_eight_euler, figure_eight_precise, outer_solar_system,
    FIGURE_EIGHT_PERIOD, FIGURE_EIGHT_PRECISE_PERIOD,
};
