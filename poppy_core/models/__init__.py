"""Servo knowledge as data: model numbers, control tables, raw ⇄ SI conversions, baud-rate codes."""

from poppy_core.models.ax import AX_12A, AX_18A
from poppy_core.models.catalog import (
    ALL_MODELS,
    STANDARD_BAUDRATES,
    model_by_name,
    model_by_number,
    standard_baudrates,
)
from poppy_core.models.converters import (
    Baudrate,
    Boolean,
    Choice,
    Converter,
    DirectionBit,
    Linear,
    Raw,
    SIValue,
)
from poppy_core.models.model import COMMON_NAMES, ServoModel
from poppy_core.models.mx import MX_12W, MX_28, MX_64, MX_106
from poppy_core.models.register import Register
from poppy_core.models.xl320 import XL_320, XL320LEDColors
from poppy_core.models.xseries import XL330_M288, XL430_W250, XM430_W350

__all__ = [
    "ALL_MODELS",
    "AX_12A",
    "AX_18A",
    "COMMON_NAMES",
    "MX_12W",
    "MX_28",
    "MX_64",
    "MX_106",
    "STANDARD_BAUDRATES",
    "XL330_M288",
    "XL430_W250",
    "XL_320",
    "XM430_W350",
    "Baudrate",
    "Boolean",
    "Choice",
    "Converter",
    "DirectionBit",
    "Linear",
    "Raw",
    "Register",
    "SIValue",
    "ServoModel",
    "XL320LEDColors",
    "model_by_name",
    "model_by_number",
    "standard_baudrates",
]
