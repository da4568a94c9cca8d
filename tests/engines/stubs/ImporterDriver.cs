// Runs MeasuredBrdfImporter on one file against the stubs and writes what it produced:
//   driver.exe FILE OUT_PREFIX [half]  →  OUT_PREFIX.json (texture settings) and OUT_PREFIX.bin
//   (the uint words for E5B9G9R9, or the floats handed to Mathf.FloatToHalf for the fallback).
using System;
using System.IO;
using UnityEditor.AssetImporters;
using UnityEngine;

public static class ImporterDriver
{
    public static int Main(string[] args)
    {
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
            else foreach (float f in Mathf.HalfInputs) bin.Write(f);
        }
        return 0;
    }
}
