//! Every Linux binary the FMUs ship loads on glibc 2.17 (the manylinux2014 baseline: RHEL/Rocky 7
//! to 9, Ubuntu 18.04 and later, Debian 10 and later): no symbol version it needs is newer. The
//! versions are read from the ELF file's version-needs section (`.gnu.version_r`, what `readelf -V`
//! lists), parsed here.

use std::io::Read;
use std::path::Path;

/// The newest glibc a shipped binary may need.
const BASELINE: (u32, u32) = (2, 17);

fn u16_at(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes(b[at..at + 2].try_into().unwrap())
}
fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}
fn u64_at(b: &[u8], at: usize) -> usize {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap()) as usize
}
fn c_string(b: &[u8], at: usize) -> String {
    let end = b[at..].iter().position(|&c| c == 0).unwrap() + at;
    String::from_utf8_lossy(&b[at..end]).into_owned()
}

/// The ELF machine (62 x86-64, 183 AArch64) and the version names each needed library is asked
/// for, as (library, version). A 64-bit little-endian ELF file only.
fn needed_versions(elf: &[u8]) -> (u16, Vec<(String, String)>) {
    assert_eq!(&elf[..4], b"\x7fELF", "not an ELF file");
    assert_eq!(
        (elf[4], elf[5]),
        (2, 1),
        "not a 64-bit little-endian ELF file"
    );
    let machine = u16_at(elf, 18);
    let (shoff, shentsize, shnum) = (u64_at(elf, 40), u16_at(elf, 58), u16_at(elf, 60));
    let section = |i: usize| {
        let h = shoff + i * shentsize as usize;
        // (type, file offset, link)
        (u32_at(elf, h + 4), u64_at(elf, h + 24), u32_at(elf, h + 40))
    };
    const SHT_GNU_VERNEED: u32 = 0x6fff_fffe;
    let mut out = Vec::new();
    for i in 0..shnum as usize {
        let (kind, offset, link) = section(i);
        if kind != SHT_GNU_VERNEED {
            continue;
        }
        let strings = section(link as usize).1;
        // Elf64_Verneed: version u16, count u16, file u32, aux u32, next u32.
        let mut need = offset;
        loop {
            let (count, file) = (u16_at(elf, need + 2), u32_at(elf, need + 4));
            let library = c_string(elf, strings + file as usize);
            // Elf64_Vernaux: hash u32, flags u16, other u16, name u32, next u32.
            let mut aux = need + u32_at(elf, need + 8) as usize;
            for _ in 0..count {
                let name = c_string(elf, strings + u32_at(elf, aux + 8) as usize);
                out.push((library.clone(), name));
                aux += u32_at(elf, aux + 12) as usize;
            }
            match u32_at(elf, need + 12) {
                0 => break,
                next => need += next as usize,
            }
        }
    }
    (machine, out)
}

/// The newest `GLIBC_x.y` among the versions (GLIBC_PRIVATE and others aside).
fn newest_glibc(versions: &[(String, String)]) -> Option<(u32, u32)> {
    versions
        .iter()
        .filter_map(|(_, v)| v.strip_prefix("GLIBC_"))
        .filter_map(|v| {
            let mut parts = v.split('.').map(|p| p.parse::<u32>().ok());
            Some((parts.next()??, parts.next().flatten().unwrap_or(0)))
        })
        .max()
}

/// The positive control: this test binary, linked by the host's toolchain against a current
/// glibc, needs versions above the baseline, and the parser sees them.
#[test]
fn the_parser_sees_a_host_binary_need_a_newer_glibc() {
    let me = std::fs::read("/proc/self/exe").unwrap();
    let (_, versions) = needed_versions(&me);
    let newest = newest_glibc(&versions).expect("no GLIBC version found in this test binary");
    assert!(
        newest > BASELINE,
        "this test binary needs only GLIBC_{}.{}: the control cannot tell a failure",
        newest.0,
        newest.1
    );
}

#[test]
fn every_shipped_linux_binary_needs_at_most_glibc_2_17() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/fmu");
    let mut fmus: Vec<_> = std::fs::read_dir(&dir)
        .expect("no target/fmu: run `make fmus`")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "fmu"))
        .collect();
    fmus.sort();
    assert!(fmus.len() >= 7, "{} FMUs in target/fmu", fmus.len());
    let mut report = Vec::new();
    for fmu in &fmus {
        let mut zip = zip::ZipArchive::new(std::fs::File::open(fmu).unwrap()).unwrap();
        let names: Vec<String> = zip.file_names().map(String::from).collect();
        let mut linux64 = false;
        for name in names.iter().filter(|n| n.ends_with(".so")) {
            let (platform, machine) = match name.split('/').nth(1) {
                Some("linux64") => ("linux64", 62),
                Some("aarch64-linux") => ("aarch64-linux", 183),
                other => panic!("{}: {name}: unknown platform {other:?}", fmu.display()),
            };
            linux64 |= platform == "linux64";
            let mut bytes = Vec::new();
            zip.by_name(name).unwrap().read_to_end(&mut bytes).unwrap();
            let (elf_machine, versions) = needed_versions(&bytes);
            assert_eq!(
                elf_machine,
                machine,
                "{}: {name}: wrong ELF machine",
                fmu.display()
            );
            let newest = newest_glibc(&versions).unwrap_or((0, 0));
            let too_new: Vec<_> = versions
                .iter()
                .filter(|(_, v)| newest_glibc(&[(String::new(), v.clone())]) > Some(BASELINE))
                .collect();
            assert!(
                too_new.is_empty(),
                "{}: {name} needs {too_new:?}, newer than GLIBC_{}.{}: it will not load on older Linux",
                fmu.display(),
                BASELINE.0,
                BASELINE.1
            );
            report.push(format!("{name}: GLIBC_{}.{}", newest.0, newest.1));
        }
        assert!(linux64, "{}: no binaries/linux64", fmu.display());
    }
    println!("{}", report.join("\n"));
}
