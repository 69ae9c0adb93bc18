/* A stand-in for Windows 10's bcryptprimitives.dll, for the Wine tests only; never shipped.
 *
 * Rust's standard library (1.78 and later) takes its randomness from ProcessPrng in
 * bcryptprimitives.dll, which every Windows the products support has. Wine 8 (Debian 12's) lacks
 * it, so every Rust program stops at load with status c0000135 there. This DLL exports the one
 * function over RtlGenRandom (advapi32's SystemFunction036), which Wine has; the tests put it
 * in the throw-away Wine prefix's system32, so it is never beside an installed product.
 *
 *   x86_64-w64-mingw32-gcc -shared -O2 -o bcryptprimitives.dll process_prng.c -ladvapi32
 */
#include <windows.h>

BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length);

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length) {
    while (length > 0) {
        ULONG chunk = length > 0x40000000 ? 0x40000000 : (ULONG)length;
        if (!SystemFunction036(data, chunk)) return FALSE;
        data += chunk;
        length -= chunk;
    }
    return TRUE;
}
