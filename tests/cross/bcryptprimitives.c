/* Stand-in for Windows 10's bcryptprimitives.dll, which wine 8.0 lacks: Rust's standard library
 * (>= 1.78) imports ProcessPrng from it. Placed next to the test harness .exe only; real Windows
 * ships its own. RtlGenRandom is advapi32's SystemFunction036. */
#include <windows.h>

BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length);

BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length) {
    while (length > 0) {
        ULONG chunk = length > 0x10000000 ? 0x10000000 : (ULONG)length;
        if (!SystemFunction036(data, chunk))
            return FALSE;
        data += chunk;
        length -= chunk;
    }
    return TRUE;
}
