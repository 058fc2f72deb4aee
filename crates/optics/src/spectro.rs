//! spectro (to come)
