"""Control layer: feedback laws acting on the true or the estimated state.

Linear state feedback (Sun et al. 2011's orbit maneuver), and the active
disturbance rejection control of Yang et al. (2020): Han's fal, the nonlinear
PID and the drag-free ADRC laws.
"""

from .adrc import DragFreeADRC, NonlinearPID, fal
from .feedback import SOURCES, LinearFeedback

__all__ = ["LinearFeedback", "SOURCES", "fal", "NonlinearPID", "DragFreeADRC"]
