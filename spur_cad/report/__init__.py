"""Figures and the report: matplotlib through its object API only (no pyplot state), report.html from a Jinja2
template (templates/report.html.j2)."""
