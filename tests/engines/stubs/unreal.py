"""A stand-in for Unreal Engine 5's `unreal` Python module with the names
import_measured_brdf.py uses, recording every call into RECORD (dumped to $UNREAL_STUB_LOG as
JSON at exit) so tests/engines/engine_handoff_checks.py can check what the script asks the
editor to do. Not Unreal: only enough to run the script, but with the API's property names
(_PROPERTIES): setting or reading one a class does not have fails as in the editor."""
import atexit
import json
import os

RECORD = []


def _enum(name, members):
    cls = type(name, (), {})
    for m in members:
        setattr(cls, m, f"{name}.{m}")
    return cls


# Members as the UE5 Python API lists them (unreal.TextureCompressionSettings: TC_HDR = 6,
# TC_HDR_COMPRESSED = 10, "HDR Compressed (RGB, BC6H, DX11)").
TextureCompressionSettings = _enum("TextureCompressionSettings",
                                   ["TC_DEFAULT", "TC_HDR", "TC_HDR_COMPRESSED"])
TextureMipGenSettings = _enum("TextureMipGenSettings", ["TMGS_FROM_TEXTURE_GROUP", "TMGS_NO_MIPMAPS"])
TextureFilter = _enum("TextureFilter", ["TF_DEFAULT", "TF_BILINEAR", "TF_TRILINEAR"])
TextureAddress = _enum("TextureAddress", ["TA_WRAP", "TA_CLAMP", "TA_MIRROR"])


# The editor properties each class has in the UE5 Python API reference
# (dev.epicgames.com/documentation/en-us/unreal-engine/python-api: unreal.AssetImportTask,
# unreal.Texture, unreal.Texture2D, unreal.VolumeTexture), with the inherited ones of
# unreal.Texture, as far as an import script may set them. A name outside its class's list is
# refused as Unreal refuses it, so a misspelt or invented property fails the script here.
_TEXTURE_PROPERTIES = {"adjust_brightness", "adjust_brightness_curve", "adjust_hue",
                       "adjust_max_alpha", "adjust_min_alpha", "adjust_rgb_curve",
                       "adjust_saturation", "adjust_vibrance", "alpha_coverage_thresholds",
                       "asset_user_data", "chroma_key_color", "chroma_key_texture",
                       "chroma_key_threshold", "composite_power", "composite_texture",
                       "composite_texture_mode", "compression_no_alpha", "compression_none",
                       "compression_quality", "compression_settings", "defer_compression",
                       "do_scale_mips_for_alpha_coverage", "filter", "flip_green_channel",
                       "lod_bias", "lod_group", "max_texture_size", "mip_gen_settings",
                       "mip_load_options", "never_stream", "num_cinematic_mip_levels",
                       "power_of_two_mode", "preserve_border", "srgb", "use_legacy_gamma",
                       "virtual_texture_streaming"}
_PROPERTIES = {
    "AssetImportTask": {"async_", "automated", "destination_name", "destination_path", "factory",
                        "filename", "imported_object_paths", "options", "replace_existing",
                        "replace_existing_settings", "result", "save"},
    "Texture2D": _TEXTURE_PROPERTIES | {"address_x", "address_y"},
    "VolumeTexture": _TEXTURE_PROPERTIES | {"address_mode", "source2d_texture",
                                            "source2d_tile_size_x", "source2d_tile_size_y"},
    "VolumeTextureFactory": {"create_new", "edit_after_new", "editor_import",
                             "import_priority", "initial_texture", "supported_class"},
}


class _Object:
    def __init__(self, name):
        self.name = name
        self.props = {}

    def _check(self, key):
        allowed = _PROPERTIES.get(type(self).__name__)
        if allowed is not None and key not in allowed:
            raise Exception(f"Failed to find property '{key}' for attribute '{key}' on "
                            f"'{type(self).__name__}'")

    def set_editor_property(self, key, value):
        self._check(key)
        self.props[key] = value
        RECORD.append({"object": self.name, "type": type(self).__name__, "set": key,
                       "value": value if isinstance(value, (str, int, float, bool)) else getattr(value, "name", str(value))})

    def get_editor_property(self, key):
        self._check(key)
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
