//! Five-axis machine kinematics: inverse/forward, limits, solution choice, reverse-motion smoothing, linearisation control.
