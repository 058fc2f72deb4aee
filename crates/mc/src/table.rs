//! Profile tables (in progress).
