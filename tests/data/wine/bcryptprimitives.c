/* A stand-in for Windows' bcryptprimitives.dll under Wine 8 (Debian 12),
 * which lacks it (Wine has it from 9.0 on): Rust's standard library for
 * Windows asks it for random bytes (ProcessPrng, Windows 10 and later) when
 * the program starts, and without it the loader refuses axcomp.exe.
 *
 * Only tests/it/windows.rs uses it: it is built with mingw-w64 into the
 * test's own Wine prefix, never into the zip (real Windows has the DLL). */
#include <windows.h>

/* advapi32's RtlGenRandom. */
BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length);

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length)
{
    while (length > 0) {
        ULONG chunk = length > 0x40000000 ? 0x40000000 : (ULONG)length;
        if (!SystemFunction036(data, chunk))
            return FALSE;
        data += chunk;
        length -= chunk;
    }
    return TRUE;
}
