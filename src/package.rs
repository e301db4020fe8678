//! Packaging of FMUs.
