//! Reading and writing point lists and curves (CSV/whitespace text and JSON).
