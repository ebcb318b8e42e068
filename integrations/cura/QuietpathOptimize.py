# quietpath as an Ultimaker Cura post-processing script.
#
# Install: copy this file into Cura's scripts folder (Help > Show Configuration Folder, then
# scripts/), restart Cura, and add "quietpath optimize" under Extensions > Post Processing >
# Modify G-Code. It writes the sliced G-code to a temporary file, runs
# `quietpath optimize --in-place` on it (VTG, arcs where the firmware runs them, true time
# estimates), and hands the result back to Cura. If quietpath fails, the G-code is returned
# unchanged and the error is shown in Cura's log.
#
# Cura passes the G-code as a list of layer chunks; the optimised file comes back as one
# chunk, which Cura writes as it is (put this script last in the list).

import json
import os
import subprocess
import tempfile

try:
    from ..Script import Script
except ImportError:  # run outside Cura (tests): the caller provides Script
    from Script import Script


class QuietpathOptimize(Script):
    def getSettingDataString(self):
        return json.dumps({
            "name": "quietpath optimize",
            "key": "QuietpathOptimize",
            "metadata": {},
            "version": 2,
            "settings": {
                "executable": {
                    "label": "quietpath executable",
                    "description": "Path of the quietpath command-line tool.",
                    "type": "str",
                    "default_value": "quietpath",
                },
                "extra_args": {
                    "label": "Extra arguments",
                    "description": "More options, e.g. --config /path/quietpath.toml or --tolerance 0.05.",
                    "type": "str",
                    "default_value": "",
                },
            },
        })

    def execute(self, data):
        exe = self.getSettingValueByKey("executable") or "quietpath"
        extra = (self.getSettingValueByKey("extra_args") or "").split()
        fd, path = tempfile.mkstemp(suffix=".gcode")
        try:
            with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
                f.write("".join(data))
            done = subprocess.run([exe, "optimize", "--in-place", *extra, path],
                                  capture_output=True, text=True)
            if done.returncode != 0:
                self._log("quietpath failed, G-code left as sliced: " + done.stderr.strip())
                return data
            with open(path, encoding="utf-8", newline="") as f:
                return [f.read()]
        except OSError as e:
            self._log("quietpath could not run, G-code left as sliced: %s" % e)
            return data
        finally:
            if os.path.exists(path):
                os.remove(path)

    def _log(self, message):
        try:
            from UM.Logger import Logger
            Logger.log("w", message)
        except ImportError:
            print(message)
