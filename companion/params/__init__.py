"""Parameters: declarations beside their owner, a typed store, atomic persistence."""

from companion.params.store import ParamDecl, ParamError, ParamStore

__all__ = ["ParamDecl", "ParamError", "ParamStore"]
