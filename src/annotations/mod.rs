//! Reading annotated frames (SPEC §4.1) from every supported format into one type (issue 3).
