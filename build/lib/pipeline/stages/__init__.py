"""Stage wrappers: read canonical tables, call the pure functions, write tables atomically. One module per stage."""
