"""The report figures' PNGs (spur_cad.report.plots.png_bytes, the canvas's pixels saved by Pillow): what Pillow reads
back is the drawn image, pixel for pixel, at the figures' resolution."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from spur_cad.report.plots import PNG_DPI, _png, figure, png_bytes


def test_png_bytes_read_back_give_the_same_pixels_and_resolution():
    rgb = np.random.default_rng(7).integers(0, 256, size=(37, 53, 3), dtype=np.uint8)  # not square, odd sizes
    image = Image.open(io.BytesIO(png_bytes(rgb, PNG_DPI)))
    assert image.mode == "RGB" and image.size == (53, 37)
    assert np.array_equal(np.asarray(image), rgb)
    assert image.info["dpi"] == pytest.approx((PNG_DPI, PNG_DPI), abs=0.05)  # whole pixels per metre


def test_a_report_figure_is_its_size_in_inches_at_120_dpi_and_draws_its_line():
    fig = figure(7.5, 2.6)
    ax = fig.add_subplot(1, 1, 1)
    ax.plot([0.0, 1.0], [0.0, 1.0], "-", color="tab:red", lw=3.0)
    image = np.asarray(Image.open(io.BytesIO(_png(fig))))
    assert image.shape == (round(2.6 * PNG_DPI), round(7.5 * PNG_DPI), 3)
    red = np.all(np.abs(image.astype(int) - (0xD6, 0x27, 0x28)) < 8, axis=2)  # tab:red
    assert red.sum() > 500 and np.all(image[0] == 255)  # the line drawn, the top row the white background
