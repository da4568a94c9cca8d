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
        public static bool E5Supported = true;
        public static bool IsFormatSupported(Experimental.Rendering.GraphicsFormat format,
                                             Experimental.Rendering.FormatUsage usage)
        {
            return format != Experimental.Rendering.GraphicsFormat.E5B9G9R9_UFloatPack32 || E5Supported;
        }
    }
}

namespace UnityEngine.Experimental.Rendering
{
    public enum GraphicsFormat { None = 0, R16G16B16A16_SFloat = 48, E5B9G9R9_UFloatPack32 = 74 }
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
