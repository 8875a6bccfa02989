//! Kinematic flapping after Wu & Popović (issue 7).
