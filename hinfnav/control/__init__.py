"""Control layer: feedback laws acting on the true or the estimated state."""

from .feedback import SOURCES, LinearFeedback

__all__ = ["LinearFeedback", "SOURCES"]
