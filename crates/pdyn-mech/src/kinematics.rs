//! Kinematics of a particle (issue 7, in progress).
