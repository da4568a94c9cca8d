// Runs MeasuredBrdfImporter on one file against the stubs and writes what it produced:
//   driver.exe FILE OUT_PREFIX [half]  →  OUT_PREFIX.json (texture settings) and OUT_PREFIX.bin
//   (the uint words for E5B9G9R9, the blocks for BC6H, or the floats handed to
//   Mathf.FloatToHalf for the fallback);
//   driver.exe flipbook FILE WIDTH HEIGHT OUT_PREFIX  →  OUT_PREFIX.json: the settings
//   MeasuredBrdfFlipbookPostprocessor leaves on a TextureImporter for a source of that size.
using System;
using System.IO;
using System.Reflection;
using UnityEditor;
using UnityEditor.AssetImporters;
using UnityEngine;

public static class ImporterDriver
{
    static string Platform(TextureImporter importer, string name)
    {
        TextureImporterPlatformSettings p;
        if (!importer.platforms.TryGetValue(name, out p)) return "null";
        return "{\"name\": \"" + p.name + "\", \"overridden\": " + (p.overridden ? "true" : "false") +
               ", \"format\": \"" + p.format + "\", \"textureCompression\": \"" + p.textureCompression +
               "\", \"crunchedCompression\": " + (p.crunchedCompression ? "true" : "false") +
               ", \"maxTextureSize\": " + p.maxTextureSize + "}";
    }

    static int Flipbook(string[] args)
    {
        var importer = new TextureImporter { assetPath = args[1], sourceWidth = int.Parse(args[2]), sourceHeight = int.Parse(args[3]) };
        var post = new MeasuredBrdfFlipbookPostprocessor { assetPath = args[1], assetImporter = importer };
        // Unity calls the message by name.
        typeof(MeasuredBrdfFlipbookPostprocessor).GetMethod("OnPreprocessTexture", BindingFlags.Instance | BindingFlags.NonPublic | BindingFlags.Public).Invoke(post, null);
        var s = importer.settings;
        using (var json = new StreamWriter(args[4] + ".json"))
            json.Write("{\"errors\": [" + string.Join(", ", Debug.Errors.ConvertAll(e => "\"" + e.Replace("\"", "'") + "\"")) + "]" +
                       ", \"textureShape\": \"" + s.textureShape + "\", \"flipbookColumns\": " + s.flipbookColumns +
                       ", \"flipbookRows\": " + s.flipbookRows + ", \"sRGBTexture\": " + (s.sRGBTexture ? "true" : "false") +
                       ", \"mipmapEnabled\": " + (s.mipmapEnabled ? "true" : "false") + ", \"npotScale\": \"" + s.npotScale +
                       "\", \"wrapMode\": \"" + s.wrapMode + "\", \"filterMode\": \"" + s.filterMode +
                       "\", \"alphaSource\": \"" + s.alphaSource + "\", \"textureCompression\": \"" + importer.textureCompression +
                       "\", \"crunchedCompression\": " + (importer.crunchedCompression ? "true" : "false") +
                       ", \"standalone\": " + Platform(importer, "Standalone") + "}\n");
        return 0;
    }

    public static int Main(string[] args)
    {
        if (args[0] == "flipbook") return Flipbook(args);
        SystemInfo.E5Supported = !(args.Length > 2 && args[2] == "half");
        var ctx = new AssetImportContext(args[0]);
        new MeasuredBrdfImporter().OnImportAsset(ctx);
        var attr = (ScriptedImporterAttribute)Attribute.GetCustomAttribute(typeof(MeasuredBrdfImporter), typeof(ScriptedImporterAttribute));
        var t = ctx.mainObject as Texture3D;
        using (var json = new StreamWriter(args[1] + ".json"))
        {
            json.Write("{\"errors\": [" + string.Join(", ", ctx.errors.ConvertAll(e => "\"" + e.Replace("\\", "/").Replace("\"", "'") + "\"")) + "]");
            json.Write(", \"extensions\": [\"" + string.Join("\", \"", attr.fileExtensions) + "\"], \"override_extensions\": [\"" + string.Join("\", \"", attr.overrideFileExtensions) + "\"]");
            if (t != null)
                json.Write(", \"width\": " + t.width + ", \"height\": " + t.height + ", \"depth\": " + t.depth +
                           ", \"format\": \"" + t.graphicsFormat + "\", \"wrap\": \"" + t.wrapMode + "\", \"filter\": \"" + t.filterMode +
                           "\", \"aniso\": " + t.anisoLevel + ", \"applied\": " + (t.applied ? "true" : "false") +
                           ", \"mipmaps_updated\": " + (t.applyUpdateMipmaps ? "true" : "false") + ", \"name\": \"" + t.name + "\"");
            json.Write("}\n");
        }
        using (var bin = new BinaryWriter(File.Create(args[1] + ".bin")))
        {
            if (t != null && t.pixelData is uint[] words) foreach (uint w in words) bin.Write(w);
            else if (t != null && t.pixelData is byte[] blocks) bin.Write(blocks);
            else foreach (float f in Mathf.HalfInputs) bin.Write(f);
        }
        return 0;
    }
}
