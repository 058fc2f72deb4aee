//! Spectrophotometer CSV (to come).
