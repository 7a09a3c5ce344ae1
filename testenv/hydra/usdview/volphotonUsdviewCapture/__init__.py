"""A usdview plug-in for testenv/hydra/test_usdview.py: captures the viewport once the renderer
has refined to a number of passes, then closes usdview.

Loaded by libplug (plugInfo.json beside this file on PXR_PLUGINPATH_NAME, its parent folder on
PYTHONPATH). It does nothing unless VOLPHOTON_USDVIEW_CAPTURE names the PNG to write:

| variable                     | meaning                                                            |
|------------------------------|--------------------------------------------------------------------|
| VOLPHOTON_USDVIEW_CAPTURE    | PNG of the viewport (GrabViewportShot); a JSON report beside it     |
| VOLPHOTON_USDVIEW_SIZE       | "W H": the viewport widget is fixed to this size (the camera's aspect) |
| VOLPHOTON_USDVIEW_PASSES     | capture once the render stats report at least this many passes     |
| VOLPHOTON_USDVIEW_TIMEOUT    | seconds before giving up (the report then says why)                |

Once the passes are reached (and at least SETTLE_SECONDS after the resize) it pauses the render
(usdview's Renderer > Pause), waits until the pass in flight has landed, grabs the viewport and
writes the report (`<capture>.json`): the renderer id, the passes the image holds (`passes`, and
`passesAfterGrab` as a check), whether the renderer said it was converged, the image size; or
`error`.
"""

import json
import os
import time

from pxr import Tf
from pxr.Usdviewq.plugin import PluginContainer

SETTLE_SECONDS = 1.0


class _Capture(object):
    def __init__(self, usdviewApi, out):
        from pxr.Usdviewq.qt import QtCore
        self._api = usdviewApi
        self._out = out
        self._size = [int(x) for x in os.environ.get("VOLPHOTON_USDVIEW_SIZE", "256 144").split()]
        self._passes = int(os.environ.get("VOLPHOTON_USDVIEW_PASSES", "16"))
        self._deadline = time.time() + float(os.environ.get("VOLPHOTON_USDVIEW_TIMEOUT", "120"))
        self._pausedAt = None  # passes when the render was paused
        self._timer = QtCore.QTimer()
        self._timer.setInterval(250)
        self._timer.timeout.connect(self._poll)
        QtCore.QTimer.singleShot(0, self._setUp)

    def _stageView(self):
        from pxr.Usdviewq.stageView import StageView
        return self._api.qMainWindow.findChild(StageView)

    def _setUp(self):
        from pxr.Usdviewq.common import ColorCorrectionModes
        settings = self._api.dataModel.viewSettings
        settings.showHUD = False  # the HUD text would be drawn over the image
        settings.colorCorrectionMode = ColorCorrectionModes.SRGB  # pinned: the test applies the same
        self._stageView().setFixedSize(*self._size)
        self._setUpTime = time.time()
        self._timer.start()

    def _stats(self):
        # The viewport's UsdImagingGL.Engine: usdview has no public accessor for its render stats.
        renderer = getattr(self._stageView(), "_renderer", None)
        return (renderer.GetRenderStats(), renderer.IsConverged()) if renderer else ({}, False)

    def _poll(self):
        stats, _ = self._stats()
        passes = int(stats.get("passes", 0))
        now = time.time()
        if self._pausedAt is None:
            # SETTLE_SECONDS first: the resized viewport has been drawn (a renderer restarted) by then.
            if passes >= self._passes and now > self._setUpTime + SETTLE_SECONDS:
                # Paused, the render thread finishes its pass in flight and starts no other, so the
                # image grabbed holds a known number of passes.
                self._stageView().SetRendererPaused(True)
                self._pausedAt, self._stableSince = passes, now
        elif passes != self._pausedAt:
            self._pausedAt, self._stableSince = passes, now  # the pass in flight landed
        elif now - self._stableSince > max(0.5, 3 * float(stats.get("totalSeconds", 0)) / max(1, passes)):
            # Unchanged for three times the mean pass time: no pass is in flight any more.
            self._timer.stop()
            image = self._api.GrabViewportShot()
            after, converged = self._stats()
            image.save(self._out)
            self._finish(passes=passes, passesAfterGrab=int(after.get("passes", 0)), converged=converged,
                         width=image.width(), height=image.height())
            return
        if time.time() > self._deadline:
            self._timer.stop()
            self._finish(error="%d passes after the timeout (wanted %d); stats %s" % (passes, self._passes, dict(stats)))

    def _finish(self, **report):
        report["renderer"] = str(self._api.GetViewportCurrentRendererId())
        with open(os.path.splitext(self._out)[0] + ".json", "w") as f:
            json.dump(report, f)
        self._api.qMainWindow.close()


_captures = []  # usdview keeps no reference to plug-in containers once they are loaded


class CaptureContainer(PluginContainer):
    def registerPlugins(self, plugRegistry, usdviewApi):
        out = os.environ.get("VOLPHOTON_USDVIEW_CAPTURE")
        if out:
            _captures.append(_Capture(usdviewApi, out))

    def configureView(self, plugRegistry, plugUIBuilder):
        pass


Tf.Type.Define(CaptureContainer)
