"""Set-up of the Hydra tests (run by tools/test.sh only where the build found OpenUSD with imaging).

usdrecord is OpenUSD's own command (its Python, its pxr), run in a subprocess with:
  * PXR_PLUGINPATH_NAME: this build's hdVolPhoton delegate, glTF file-format plug-in and medium
    schemas (plugInfo.json made for this OpenUSD), installed into build/hydra-stage by `cmake --install`;
  * usdrecord's default scene path (the legacy scene delegate in OpenUSD 24.08);
    USDIMAGINGGL_ENGINE_ENABLE_SCENE_INDEX=1 only where a test asks for the scene-index path.
A missing usdrecord or plug-in is a failure here, not a skip: tools/test.sh prints the SKIPPED line
when there is no OpenUSD build at all.
"""

import pytest

from hydra_util import make_hydra_env


@pytest.fixture(scope="session")
def hydra_env():
    return make_hydra_env()
