// libsake_glug for .NET through P/Invoke, the way Unity and Godot's C# side call native code:
// put libsake_glug.so (or sake_glug.dll, libsake_glug.dylib) where the runtime finds native
// libraries (Unity: Assets/Plugins; Mono: LD_LIBRARY_PATH). The declarations follow
// include/sake_glug.h; the threading and real-time rules are the header's: Process, State and
// Units on the audio thread (Unity's OnAudioFilterRead, Godot's AudioStreamGenerator filler), the
// control calls from any thread. Those calls answer with a Status and never throw or allocate.
using System;
using System.Runtime.InteropServices;
using System.Text;

namespace SakeGlug
{
    public enum Status : int
    {
        Ok = 0, NullHandle = 1, NullPointer = 2, InvalidControl = 3, NotFinite = 4,
        OutOfRange = 5, InvalidSize = 6, QueueFull = 7, Panicked = 8, Failed = 9,
    }

    public enum Control : int { Tilt = 0, Viscosity = 1, Fill = 2, PourTime = 3, Gain = 4 }

    [StructLayout(LayoutKind.Sequential)]
    public struct Range { public double Min, Max, DefaultValue; }

    [StructLayout(LayoutKind.Sequential)]
    public struct State
    {
        public ulong Position, ActiveUntil;
        public double VolumeMl, OutflowMlPerS, TiltDeg, OutputGain;
        public uint Submerged, Settled, Units, UnitsLost;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct Unit
    {
        public uint Frame, Audible;
        public ulong Sample;
        public double Fraction, TiltDeg, VolumeMl, PocketMl, Amplitude, ViscosityC;
        public double F1Hz, F2Hz, B1PerS, B2PerS;
    }

    public class SakeGlugException : Exception
    {
        public SakeGlugException(string message) : base(message) { }
    }

    internal static class Native
    {
        const string Library = "sake_glug";
        [DllImport(Library)] internal static extern uint sake_glug_abi_version();
        [DllImport(Library)] internal static extern ulong sake_glug_default_seed();
        [DllImport(Library)] internal static extern IntPtr sake_glug_status_text(int status);
        [DllImport(Library)] internal static extern Status sake_glug_control_range(int control, out Range range);
        [DllImport(Library)] internal static extern IntPtr sake_glug_create(double sampleRate, byte[] modelText, ulong seed);
        [DllImport(Library)] internal static extern IntPtr sake_glug_create_preset(double sampleRate, byte[] name, ulong seed);
        [DllImport(Library)] internal static extern UIntPtr sake_glug_last_error(byte[] buffer, UIntPtr capacity);
        [DllImport(Library)] internal static extern void sake_glug_destroy(IntPtr glug);
        [DllImport(Library)] internal static extern Status sake_glug_set(IntPtr glug, int control, double value);
        [DllImport(Library)] internal static extern Status sake_glug_ramp(IntPtr glug, int control, double target, ulong samples);
        [DllImport(Library)] internal static extern Status sake_glug_refill(IntPtr glug);
        [DllImport(Library)] internal static extern Status sake_glug_reset(IntPtr glug);
        [DllImport(Library)] internal static extern Status sake_glug_process(IntPtr glug, float[] output, UIntPtr frames);
        [DllImport(Library)] internal static extern Status sake_glug_process_interleaved(IntPtr glug, float[] output, UIntPtr frames, UIntPtr channels);
        [DllImport(Library)] internal static extern Status sake_glug_state(IntPtr glug, out State state);
        [DllImport(Library)] internal static extern Status sake_glug_units(IntPtr glug, [Out] Unit[] units, UIntPtr capacity, out UIntPtr count);
    }

    /// One live glug. Dispose it (or let a using block) to free the native handle.
    public sealed class Glug : IDisposable
    {
        /// The header this binding follows; the library must implement the same.
        public const uint AbiVersion = 1;
        IntPtr handle;

        /// The paper's bottle (modelText null) or a model file's text; throws SakeGlugException
        /// with the library's message.
        public Glug(double sampleRate, string modelText = null, ulong? seed = null)
            : this(Native.sake_glug_create(sampleRate, Nul(modelText), seed ?? Native.sake_glug_default_seed()))
        {
        }

        /// A shipped preset by name (a file name of presets/ without .toml, such as "syrup");
        /// throws SakeGlugException, whose message lists the presets if the name is unknown.
        public static Glug Preset(double sampleRate, string name, ulong? seed = null) =>
            new Glug(Native.sake_glug_create_preset(sampleRate, Nul(name), seed ?? Native.sake_glug_default_seed()));

        static byte[] Nul(string text) => text == null ? null : Encoding.UTF8.GetBytes(text + "\0");

        /// Owns what a create call returned; throws its message if that was NULL.
        Glug(IntPtr created)
        {
            handle = created;
            if (Native.sake_glug_abi_version() != AbiVersion)
                throw new SakeGlugException("libsake_glug is not the one this binding describes");
            if (handle == IntPtr.Zero)
            {
                int length = (int)Native.sake_glug_last_error(null, UIntPtr.Zero);
                var buffer = new byte[length + 1];
                Native.sake_glug_last_error(buffer, (UIntPtr)buffer.Length);
                throw new SakeGlugException(Encoding.UTF8.GetString(buffer, 0, length));
            }
        }

        public static Range RangeOf(Control control)
        {
            Range range;
            Check(Native.sake_glug_control_range((int)control, out range), "range");
            return range;
        }

        public static string Text(Status status) => Marshal.PtrToStringAnsi(Native.sake_glug_status_text((int)status));

        /// Throws unless the status is Ok (not on the audio thread: throwing allocates).
        public static void Check(Status status, string what)
        {
            if (status != Status.Ok) throw new SakeGlugException(what + ": " + Text(status));
        }

        public Status Set(Control control, double value) => Native.sake_glug_set(handle, (int)control, value);
        public Status Ramp(Control control, double target, ulong samples) => Native.sake_glug_ramp(handle, (int)control, target, samples);
        public Status Refill() => Native.sake_glug_refill(handle);
        public Status Reset() => Native.sake_glug_reset(handle);

        /// Fills all of `output` with mono samples.
        public Status Process(float[] output) => Native.sake_glug_process(handle, output, (UIntPtr)output.Length);

        /// Fills all of `output` with frames of `channels` interleaved channels (Unity's
        /// OnAudioFilterRead buffer).
        public Status ProcessInterleaved(float[] output, int channels) =>
            channels <= 0 ? Status.InvalidSize
            : Native.sake_glug_process_interleaved(handle, output, (UIntPtr)(output.Length / channels), (UIntPtr)channels);

        public Status GetState(out State state) => Native.sake_glug_state(handle, out state);

        /// Copies the units first heard in the last process call into `units`; `count` says how many.
        public Status GetUnits(Unit[] units, out int count)
        {
            UIntPtr copied;
            Status status = Native.sake_glug_units(handle, units, (UIntPtr)units.Length, out copied);
            count = (int)copied;
            return status;
        }

        public void Dispose()
        {
            Native.sake_glug_destroy(handle);
            handle = IntPtr.Zero;
            GC.SuppressFinalize(this);
        }

        ~Glug() { Native.sake_glug_destroy(handle); }
    }
}
