// Minimal stand-ins for the UnityEngine / UnityEditor types MeasuredBrdfImporter.cs uses, with
// the signatures of the Unity 2021.3-6000 scripting API, recording what the importer does so
// tests/engines/engine_handoff_checks.py can check it. Not Unity: only enough to compile and
// run the importer under mono.
using System;
using System.Collections.Generic;

namespace UnityEngine
{
    public class Object { public string name; }
    public class Texture : Object
    {
        public TextureWrapMode wrapMode;
        public FilterMode filterMode;
        public int anisoLevel;
    }
    public enum TextureWrapMode { Repeat, Clamp, Mirror, MirrorOnce }
    public enum FilterMode { Point, Bilinear, Trilinear }
    public sealed class Texture3D : Texture
    {
        public readonly int width, height, depth;
        public readonly Experimental.Rendering.GraphicsFormat graphicsFormat;
        public Array pixelData;
        public bool applied, applyUpdateMipmaps, applyMakeNoLongerReadable;
        public Texture3D(int width, int height, int depth, Experimental.Rendering.GraphicsFormat format,
                         Experimental.Rendering.TextureCreationFlags flags)
        {
            this.width = width; this.height = height; this.depth = depth; graphicsFormat = format;
            if (flags != Experimental.Rendering.TextureCreationFlags.None) throw new ArgumentException("flags");
        }
        public void SetPixelData<T>(T[] data, int mipLevel, int sourceDataStartIndex = 0)
        {
            if (mipLevel != 0 || sourceDataStartIndex != 0) throw new ArgumentException("mip/start");
            pixelData = data;
        }
        public void Apply(bool updateMipmaps, bool makeNoLongerReadable)
        {
            applied = true; applyUpdateMipmaps = updateMipmaps; applyMakeNoLongerReadable = makeNoLongerReadable;
        }
    }
    public static class Mathf
    {
        public static readonly List<float> HalfInputs = new List<float>();
        // Records the value; returns its index so the caller's array maps back to HalfInputs.
        public static ushort FloatToHalf(float value) { HalfInputs.Add(value); return 0; }
    }
    public static class SystemInfo
    {
        public static bool E5Supported = true, Bc6hSupported = true;
        public static bool IsFormatSupported(Experimental.Rendering.GraphicsFormat format,
                                             Experimental.Rendering.FormatUsage usage)
        {
            if (format == Experimental.Rendering.GraphicsFormat.RGB_BC6H_UFloat) return Bc6hSupported;
            return format != Experimental.Rendering.GraphicsFormat.E5B9G9R9_UFloatPack32 || E5Supported;
        }
    }
    public static class Debug
    {
        public static readonly List<string> Errors = new List<string>();
        public static void LogError(object message) { Errors.Add(message.ToString()); }
    }
}

// UnityEditor's texture import API as the Unity 2021.3-6000 scripting reference names it
// (AssetPostprocessor, TextureImporter, TextureImporterSettings, TextureImporterPlatformSettings
// and their enums), recording the settings a postprocessor leaves on the importer.
namespace UnityEditor
{
    public class AssetImporter { public string assetPath; }
    public class AssetPostprocessor
    {
        public string assetPath { get; set; }
        public AssetImporter assetImporter { get; set; }
    }
    public enum TextureImporterShape { Texture2D = 1, TextureCube = 2, Texture2DArray = 4, Texture3D = 8 }
    public enum TextureImporterNPOTScale { None = 0, ToNearest = 1, ToLarger = 2, ToSmaller = 3 }
    public enum TextureImporterAlphaSource { None = 0, FromInput = 1, FromGrayScale = 2 }
    public enum TextureImporterCompression { Uncompressed = 0, Compressed = 1, CompressedHQ = 2, CompressedLQ = 3 }
    public enum TextureImporterFormat { Automatic = -1, RGBAHalf = 17, BC6H = 24, BC7 = 25 }
    public sealed class TextureImporterSettings
    {
        public TextureImporterShape textureShape = TextureImporterShape.Texture2D;
        public int flipbookColumns = 1, flipbookRows = 1;
        public bool sRGBTexture = true, mipmapEnabled = true;
        public TextureImporterNPOTScale npotScale = TextureImporterNPOTScale.ToNearest;
        public UnityEngine.TextureWrapMode wrapMode = UnityEngine.TextureWrapMode.Repeat;
        public UnityEngine.FilterMode filterMode = UnityEngine.FilterMode.Bilinear;
        public TextureImporterAlphaSource alphaSource = TextureImporterAlphaSource.FromInput;
    }
    public sealed class TextureImporterPlatformSettings
    {
        public string name = "DefaultTexturePlatform";
        public bool overridden = false, crunchedCompression = false;
        public TextureImporterFormat format = TextureImporterFormat.Automatic;
        public TextureImporterCompression textureCompression = TextureImporterCompression.Compressed;
        public int maxTextureSize = 2048;
        public TextureImporterPlatformSettings Copy()
        {
            return (TextureImporterPlatformSettings)MemberwiseClone();
        }
    }
    public sealed class TextureImporter : AssetImporter
    {
        public int sourceWidth, sourceHeight;
        public TextureImporterCompression textureCompression = TextureImporterCompression.Compressed;
        public bool crunchedCompression = false;
        public TextureImporterSettings settings = new TextureImporterSettings();
        public readonly Dictionary<string, TextureImporterPlatformSettings> platforms =
            new Dictionary<string, TextureImporterPlatformSettings>();
        public void GetSourceTextureWidthAndHeight(out int width, out int height)
        {
            width = sourceWidth; height = sourceHeight;
        }
        public void ReadTextureSettings(TextureImporterSettings dest)
        {
            dest.textureShape = settings.textureShape; dest.flipbookColumns = settings.flipbookColumns;
            dest.flipbookRows = settings.flipbookRows; dest.sRGBTexture = settings.sRGBTexture;
            dest.mipmapEnabled = settings.mipmapEnabled; dest.npotScale = settings.npotScale;
            dest.wrapMode = settings.wrapMode; dest.filterMode = settings.filterMode;
            dest.alphaSource = settings.alphaSource;
        }
        public void SetTextureSettings(TextureImporterSettings src) { settings = src; }
        public TextureImporterPlatformSettings GetPlatformTextureSettings(string platform)
        {
            TextureImporterPlatformSettings p;
            if (platforms.TryGetValue(platform, out p)) return p.Copy();
            return new TextureImporterPlatformSettings { name = platform };
        }
        public void SetPlatformTextureSettings(TextureImporterPlatformSettings platformSettings)
        {
            platforms[platformSettings.name] = platformSettings.Copy();
        }
    }
}

namespace UnityEngine.Experimental.Rendering
{
    public enum GraphicsFormat { None = 0, R16G16B16A16_SFloat = 48, E5B9G9R9_UFloatPack32 = 74, RGB_BC6H_UFloat = 143 }
    public enum TextureCreationFlags { None = 0, MipChain = 1 }
    public enum FormatUsage { Sample = 0, Linear = 1 }
}

namespace UnityEditor.AssetImporters
{
    [AttributeUsage(AttributeTargets.Class)]
    public sealed class ScriptedImporterAttribute : Attribute
    {
        public int version; public string[] fileExtensions; public string[] overrideFileExtensions;
        public ScriptedImporterAttribute(int version, string[] exts, string[] overrideExts)
        {
            this.version = version; fileExtensions = exts; overrideFileExtensions = overrideExts;
        }
    }
    public abstract class ScriptedImporter
    {
        public abstract void OnImportAsset(AssetImportContext ctx);
    }
    public class AssetImportContext
    {
        public string assetPath { get; }
        public UnityEngine.Object mainObject;
        public readonly List<string> errors = new List<string>();
        public readonly Dictionary<string, UnityEngine.Object> objects = new Dictionary<string, UnityEngine.Object>();
        public AssetImportContext(string path) { assetPath = path; }
        public void AddObjectToAsset(string identifier, UnityEngine.Object obj) { objects[identifier] = obj; }
        public void SetMainObject(UnityEngine.Object obj) { mainObject = obj; }
        public void LogImportError(string message) { errors.Add(message); }
    }
}
