"""glTF files for the Python tests, built in code: numpy arrays become one embedded buffer."""
import base64
import json

import numpy as np

_COMPONENT_TYPES = {np.dtype(np.float32): 5126, np.dtype(np.uint16): 5123, np.dtype(np.uint32): 5125}
_TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4"}


def write_gltf(path, arrays, doc):
    """Writes `doc` to `path` with `arrays` as its buffer: array k is bufferView k and
    accessor k (a 1-D array is SCALAR, an N x 3 one VEC3). Returns the path as a string."""
    data, views, accessors = b"", [], []
    for k, a in enumerate(arrays):
        a = np.ascontiguousarray(a)
        views.append({"buffer": 0, "byteOffset": len(data), "byteLength": a.nbytes})
        accessors.append({"bufferView": k, "componentType": _COMPONENT_TYPES[a.dtype],
                          "type": _TYPES[1 if a.ndim == 1 else a.shape[1]], "count": len(a)})
        data += a.tobytes()
    uri = "data:application/octet-stream;base64," + base64.b64encode(data).decode()
    full = {"asset": {"version": "2.0"}, "buffers": [{"byteLength": len(data), "uri": uri}],
            "bufferViews": views, "accessors": accessors, **doc}
    path.write_text(json.dumps(full))
    return str(path)
