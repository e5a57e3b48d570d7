//! Headless benchmark: performance tables and error against run time.
