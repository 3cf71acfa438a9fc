//! Small classic systems written in Newton form (reactions declared as unknowns), shared by
//! pdyn-mech's `derive_newton_classics` and pdyn's `derive_newton_cli` tests (issue 34).

/// The double pendulum in Newton form: two bobs, two rod tensions (T1 on bob 1 along its
/// rod, T2 along the second rod on both bobs with opposite signs). Unknowns th1'', th2'', T1, T2.
pub const DOUBLE_PENDULUM: &str = r#"
name = "double pendulum, Newton form"
gravity = "[0, -g, 0]"

[parameters]
g = 9.81
m1 = 1.0
m2 = 1.0
L1 = 1.0
L2 = 1.0

[coordinates]
th1 = { initial = 0.3, rate = 0.0 }
th2 = { initial = 0.6, rate = 0.0 }

[particles.p1]
mass = "m1"
position = "L1*[sin(th1), -cos(th1), 0]"

[particles.p2]
mass = "m2"
position = "L1*[sin(th1), -cos(th1), 0] + L2*[sin(th2), -cos(th2), 0]"

[[forces]]
kind = "reaction"
name = "T1"
on = "p1"
direction = "[-sin(th1), cos(th1), 0]"

[[forces]]
kind = "reaction"
name = "T2"
on = "p1"
direction = "[sin(th2), -cos(th2), 0]"

[[forces]]
kind = "reaction"
name = "T2"
on = "p2"
direction = "[-sin(th2), cos(th2), 0]"
"#;

/// A simple pendulum in Newton form: one bob, the rod tension T as the unknown reaction.
pub const PENDULUM: &str = r#"
name = "pendulum with a rod tension"
gravity = "[0, -g, 0]"

[parameters]
g = 9.81
m = 1.0
L = 1.0

[coordinates]
th = { initial = 0.3, rate = 0.0 }

[particles.bob]
mass = "m"
position = "L*[sin(th), -cos(th), 0]"

[[forces]]
kind = "reaction"
name = "T"
on = "bob"
direction = "[-sin(th), cos(th), 0]"
"#;
