//! Triboelectric transducers, electrical loads and the charge solver (seed Sect. 3,
//! eqs. 11–14; MODEL-NOTES §2).
