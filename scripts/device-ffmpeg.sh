#!/usr/bin/env bash
# Builds a small ffmpeg + ffprobe for a GPU machine that has no ffmpeg (and no package manager reachable):
# Debian 12's own ffmpeg source, configured with only what `render --path --video` and its checks use
# (raw RGBA frames from a pipe, libx264, MP4/Matroska, the H.264 decoder for ffprobe). Debian's ffmpeg pulls in
# ~250 MB of shared libraries; this one is two ~3 MB binaries plus libx264.
#   scripts/device-ffmpeg.sh DEST    -> DEST/ffmpeg, DEST/ffprobe, DEST/libx264.so.164
# gpu-check.sh puts DEST on PATH and LD_LIBRARY_PATH when the machine has no ffmpeg.
set -euo pipefail
dest=$(realpath -m "${1:?usage: device-ffmpeg.sh DEST}")
work=${FFMPEG_BUILD_DIR:-/tmp/pointrast-ffmpeg}
sudo=""; [ "$(id -u)" -eq 0 ] || sudo=sudo
dpkg -s libx264-dev >/dev/null 2>&1 || $sudo apt-get install -y libx264-dev
mkdir -p "$work/lists/partial" "$dest"
if ! ls "$work"/ffmpeg-*/configure >/dev/null 2>&1; then
  # Source packages without touching the system's apt sources: a private list for deb-src only.
  printf 'deb-src http://deb.debian.org/debian bookworm main\ndeb-src http://deb.debian.org/debian-security bookworm-security main\n' \
    > "$work/sources.list"
  o=(-o "Dir::Etc::SourceList=$work/sources.list" -o Dir::Etc::SourceParts=/nonexistent -o "Dir::State::Lists=$work/lists")
  apt-get "${o[@]}" update -qq
  (cd "$work" && apt-get "${o[@]}" source --download-only ffmpeg -qq && tar xf ffmpeg_*.orig.tar.xz)
fi
src=$(ls -d "$work"/ffmpeg-*/ | head -1)
cd "$src"
if [ ! -x ffprobe ]; then
  ./configure --disable-everything --disable-doc --disable-network --disable-autodetect --disable-x86asm \
    --enable-gpl --enable-libx264 --enable-static --disable-shared \
    --enable-demuxer=rawvideo,mov,matroska --enable-muxer=mp4,mov,matroska --enable-protocol=pipe,file \
    --enable-encoder=libx264,rawvideo --enable-decoder=h264,rawvideo --enable-parser=h264 \
    --enable-filter=scale,format,null,buffer,buffersink,select --enable-swscale >configure.log
  make -j"$(nproc)" >make.log 2>&1
fi
cp ffmpeg ffprobe "$dest/"
cp -L /usr/lib/x86_64-linux-gnu/libx264.so.164 "$dest/"
echo "device ffmpeg: $(du -sh "$dest" | cut -f1) in $dest"
