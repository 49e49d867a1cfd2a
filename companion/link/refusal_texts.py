"""Refusals told to the operator, at most a few a second: a flood of bad input must not
turn into a flood of STATUSTEXT that starves the link (every refusal is still counted)."""

from __future__ import annotations

from collections.abc import Callable

REFUSAL_TEXT_PERIOD_S = 0.5


class RefusalTexts:
    """Pass a refusal's text on unless one went out less than ``period_s`` ago."""

    def __init__(
        self,
        send: Callable[[str], None],
        clock_s: Callable[[], float],
        period_s: float = REFUSAL_TEXT_PERIOD_S,
    ) -> None:
        self.send = send
        self.clock_s = clock_s
        self.period_s = period_s
        self.next_s = float("-inf")
        self.held_back = 0

    def __call__(self, text: str) -> None:
        now = self.clock_s()
        if now < self.next_s:
            self.held_back += 1
            return
        self.next_s = now + self.period_s
        if self.held_back:
            text = f"{text} (+{self.held_back} more refused)"
            self.held_back = 0
        self.send(text)
