"""Plots and (later) the HTML report; matplotlib is used through its object API only (no pyplot state)."""
