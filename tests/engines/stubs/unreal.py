"""A stand-in for Unreal Engine 5's `unreal` Python module with the names
import_measured_brdf.py uses, recording every call into RECORD (dumped to $UNREAL_STUB_LOG as
JSON at exit) so tests/engines/engine_handoff_checks.py can check what the script asks the
editor to do. Not Unreal: only enough to run the script."""
import atexit
import json
import os

RECORD = []


def _enum(name, members):
    cls = type(name, (), {})
    for m in members:
        setattr(cls, m, f"{name}.{m}")
    return cls


TextureCompressionSettings = _enum("TextureCompressionSettings", ["TC_DEFAULT", "TC_HDR"])
TextureMipGenSettings = _enum("TextureMipGenSettings", ["TMGS_FROM_TEXTURE_GROUP", "TMGS_NO_MIPMAPS"])
TextureFilter = _enum("TextureFilter", ["TF_DEFAULT", "TF_BILINEAR", "TF_TRILINEAR"])
TextureAddress = _enum("TextureAddress", ["TA_WRAP", "TA_CLAMP", "TA_MIRROR"])


class _Object:
    def __init__(self, name):
        self.name = name
        self.props = {}

    def set_editor_property(self, key, value):
        self.props[key] = value
        RECORD.append({"object": self.name, "type": type(self).__name__, "set": key,
                       "value": value if isinstance(value, (str, int, float, bool)) else getattr(value, "name", str(value))})

    def get_editor_property(self, key):
        return self.props.get(key)


class Texture2D(_Object):
    pass


class VolumeTexture(_Object):
    pass


class VolumeTextureFactory(_Object):
    def __init__(self):
        super().__init__("factory")


class AssetImportTask(_Object):
    def __init__(self):
        super().__init__("task")


class _AssetTools:
    def import_asset_tasks(self, tasks):
        for t in tasks:
            filename = t.props["filename"]
            if not os.path.isfile(filename):
                raise RuntimeError("no such file " + filename)
            stem = os.path.splitext(os.path.basename(filename))[0]
            t.props["imported_object_paths"] = [t.props["destination_path"] + "/" + stem]
            kind = "VolumeTexture" if filename.endswith(".dds") else "Texture2D"
            _ASSETS[t.props["imported_object_paths"][0]] = (VolumeTexture if kind == "VolumeTexture" else Texture2D)(stem)
            RECORD.append({"import": filename, "destination": t.props["destination_path"],
                           "automated": t.props.get("automated"), "as": kind})

    def create_asset(self, name, path, cls, factory):
        RECORD.append({"create": name, "path": path, "class": cls.__name__})
        return cls(name)


_ASSETS = {}


class AssetToolsHelpers:
    @staticmethod
    def get_asset_tools():
        return _AssetTools()


class EditorAssetLibrary:
    @staticmethod
    def save_loaded_asset(asset):
        RECORD.append({"save": asset.name})
        return True


def load_asset(path):
    return _ASSETS[path]


def log(message):
    RECORD.append({"log": message})


@atexit.register
def _dump():
    with open(os.environ["UNREAL_STUB_LOG"], "w") as f:
        json.dump(RECORD, f, indent=1)
