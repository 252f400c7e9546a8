//! Compute entry points for function-level CPU-vs-GPU equivalence tests (filled in below).
