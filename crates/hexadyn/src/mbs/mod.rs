//! Minimal-coordinates multibody systems (thesis Section 3.3.3-3.3.4).
