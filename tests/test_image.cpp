// written by helper
