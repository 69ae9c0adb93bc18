// The built-in pour through the C# binding (bindings/csharp/SakeGlug.cs), written as a 48 kHz
// mono 32-bit float WAV: the same samples as `sake-glug render -o pour.wav --sample-format f32`.
//
//   cargo build --release -p sake-glug-c
//   mcs -out:pour.exe examples/csharp/Pour.cs bindings/csharp/SakeGlug.cs
//   LD_LIBRARY_PATH=target/release mono pour.exe pour.wav
using System;
using System.Collections.Generic;
using System.IO;
using SakeGlug;

static class Pour
{
    const int SampleRate = 48000;
    const int Block = 4096;

    static int Main(string[] args)
    {
        if (args.Length != 1)
        {
            Console.Error.WriteLine("usage: pour.exe OUT.wav");
            return 2;
        }
        try
        {
            var samples = new List<float>();
            State state;
            using (var glug = new Glug(SampleRate))
            {
                // The built-in scene: tilt 90° -> 135° over half a second, then held.
                Glug.Check(glug.Set(Control.Tilt, 90.0), "set");
                Glug.Check(glug.Ramp(Control.Tilt, 135.0, SampleRate / 2), "ramp");
                // Until pouring stops and every unit has decayed; the samples end where the last did.
                var block = new float[Block];
                do
                {
                    Glug.Check(glug.Process(block), "process");
                    samples.AddRange(block);
                    Glug.Check(glug.GetState(out state), "state");
                } while (state.Settled == 0);
            }
            WriteWav(args[0], samples.GetRange(0, (int)state.ActiveUntil));
            return 0;
        }
        catch (Exception error) when (error is SakeGlugException || error is IOException)
        {
            Console.Error.WriteLine("error: " + error.Message);
            return 1;
        }
    }

    // A WAV of IEEE floats (format 3): RIFF, fmt and data chunks; BinaryWriter is little-endian.
    static void WriteWav(string path, List<float> samples)
    {
        using (var writer = new BinaryWriter(File.Create(path)))
        {
            int dataBytes = samples.Count * 4;
            writer.Write(new[] { (byte)'R', (byte)'I', (byte)'F', (byte)'F' });
            writer.Write(36 + dataBytes);
            writer.Write("WAVEfmt ".ToCharArray());
            writer.Write(16);
            writer.Write((short)3);
            writer.Write((short)1);
            writer.Write(SampleRate);
            writer.Write(SampleRate * 4);
            writer.Write((short)4);
            writer.Write((short)32);
            writer.Write("data".ToCharArray());
            writer.Write(dataBytes);
            foreach (float sample in samples) writer.Write(sample);
        }
    }
}
