"""Typed configuration: build pydantic models with one readable error line."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

from seminspect.core.errors import InvalidInputError

M = TypeVar("M", bound=BaseModel)


def describe_validation_error(exc: ValidationError, what: str) -> str:
    """``invalid <what> d_check_T: Input should be greater than 0`` from a pydantic error."""
    first = exc.errors()[0]
    where = ".".join(str(part) for part in first["loc"])
    message = first["msg"].removeprefix("Value error, ")
    return f"invalid {what} {where}: {message}" if where else f"invalid {what}: {message}"


def build(model: type[M], values: Mapping[str, Any], what: str | None = None) -> M:
    """``model(**values)``, raising :class:`InvalidInputError` with the first problem."""
    try:
        return model(**values)
    except ValidationError as exc:
        raise InvalidInputError(describe_validation_error(exc, what or model.__name__)) from None
