//! Post-processing of trajectories.
