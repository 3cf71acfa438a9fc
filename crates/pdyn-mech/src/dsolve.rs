//! Closed-form solution of linear ODEs with constant coefficients (issue 7, in progress).
