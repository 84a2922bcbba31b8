"""The version of spur_cad (the foundation layer: the facade spur_cad/__init__.py and every layer read it here)."""

__version__ = "0.1.0"
