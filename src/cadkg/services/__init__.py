"""Services as every transport calls them: the table by name, the session they share, and the
frames and markers a cell shows."""
