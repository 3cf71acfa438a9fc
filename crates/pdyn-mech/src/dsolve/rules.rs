//! The 1-D rules of straight-line motion (section 3.1.3).
