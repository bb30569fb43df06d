"""matplotlib figures of an exact pixel size, drawn off-screen (Agg) and returned as BGR pictures.

The pictures of ravh_sim (plans, raid summaries, the Table-4 heat map, gallery labels) are drawn by
matplotlib; callers get a numpy BGR array so OpenCV can write it or compose it with camera images.
No pyplot: figures are plain objects, nothing global is created or kept.
"""
from __future__ import annotations

import cv2
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

DPI = 100                 # points and pixels: a 10 pt font is about 14 px high


def new_figure(width_px: int, height_px: int) -> Figure:
    """An empty white figure of exactly ``width_px`` x ``height_px`` pixels."""
    figure = Figure(figsize=(width_px / DPI, height_px / DPI), dpi=DPI, facecolor="white")
    FigureCanvasAgg(figure)
    return figure


def figure_bgr(figure: Figure) -> np.ndarray:
    """The drawn figure as a BGR uint8 picture."""
    canvas = figure.canvas
    assert isinstance(canvas, FigureCanvasAgg)
    canvas.draw()
    return cv2.cvtColor(np.asarray(canvas.buffer_rgba()), cv2.COLOR_RGBA2BGR)


def rgb(colour: tuple[int, int, int]) -> tuple[float, float, float]:
    """An 8-bit RGB colour as matplotlib's 0..1 floats."""
    return (colour[0] / 255, colour[1] / 255, colour[2] / 255)
