"""Writers: every output is written atomically and returns its path or raises ExportError."""
