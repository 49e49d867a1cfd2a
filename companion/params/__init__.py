"""Parameters: declarations beside their owner, a typed store, atomic persistence."""

from companion.params.store import ParamDecl, ParamError, ParamStore, declared_values

__all__ = ["ParamDecl", "ParamError", "ParamStore", "declared_values"]
