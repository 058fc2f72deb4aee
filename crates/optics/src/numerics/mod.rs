//! The numerics the physics crates share: bracketed roots and bisection ([`roots`]) and quadrature
//! rules ([`quadrature`]). Each is the one copy its callers use; a routine written out again
//! elsewhere differs in what it needs (a fallible function, another stopping rule).

pub mod quadrature;
pub mod roots;
