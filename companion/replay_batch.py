"""`companion replay` over many logs at once, on Ray, with a summary of navigator health."""
