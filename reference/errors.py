"""Errors raised by the reference solutions and the exact oracles."""


class ReferencePackageError(Exception):
    """Root of every error raised by the `reference` package."""


class ThresholdOutOfRangeError(ReferencePackageError, ValueError):
    """Raised when a Blackjack threshold policy is asked for an `n` outside 0..21."""


class InvalidProbabilityError(ReferencePackageError, ValueError):
    """Raised when a Blackjack policy returns a hit probability outside [0, 1]."""


class InvalidQTableError(ReferencePackageError, ValueError):
    """Raised when a Taxi Q-table does not have shape (500, 6) or is not made of real numbers."""


class InvalidParameterError(ReferencePackageError, ValueError):
    """Raised when a count, step limit or discount factor is outside its valid range."""


class UnexpectedEnvironmentError(ReferencePackageError, RuntimeError):
    """Raised when gymnasium's Taxi model is not the deterministic one the Taxi oracle is built for."""


class InvalidMdpError(ReferencePackageError, ValueError):
    """Raised when an MDP table `P[s][a]` is incomplete, leads outside its states or has bad probabilities."""


class UnboundedValueError(ReferencePackageError, ArithmeticError):
    """Raised when a policy's return has no finite value (it loops through nonzero rewards at discount 1)."""
