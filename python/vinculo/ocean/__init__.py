"""The ocean: water depth, currents and linear waves, and the flow they make
(docs/theory/ocean.md).

- :class:`Sea`: depth, current, waves; ``Sea.regular``, ``Sea.irregular`` (JONSWAP or
  Pierson-Moskowitz, long- or short-crested), or components from a measured elevation record
  (:func:`from_elevation`); ``system.set_water(sea.water())`` puts a model's lines in it;
- :class:`Current`: uniform, power-law or tabulated profiles;
- :mod:`vinculo.ocean.hull`: hulls of floating bodies (``System.add_floating_body``);
- :mod:`vinculo.ocean.spectra`: the spectra and their discretisation.
"""

from vinculo.ocean.hull import Hull, cylinder, frustum, sphere
from vinculo.ocean.sea import Current, Sea
from vinculo.ocean.spectra import (
    WaveComponents,
    components,
    from_elevation,
    jonswap,
    pierson_moskowitz,
    spreading,
)

__all__ = ["Current", "Hull", "Sea", "WaveComponents", "components", "cylinder",
           "from_elevation", "frustum", "jonswap", "pierson_moskowitz", "sphere", "spreading"]
