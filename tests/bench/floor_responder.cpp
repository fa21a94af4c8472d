/* The floor of a served round trip (issue 18): the least a program can do to answer an
 * EtherCAT frame over a raw socket. One AF_PACKET socket bound to EtherType 0x88A4 on one
 * interface, our own sends not looped back (PACKET_IGNORE_OUTGOING); each frame received
 * (one blocking recv) gets every datagram's working counter incremented by one and the
 * source MAC's locally administered bit set (as an ESC does, ESC datasheet section I §3, and
 * as topology/segment.cpp models it), and is sent back. No simulation, no
 * checks beyond not running off the frame. floor_bench measures it beside `ecsim serve`.
 *
 *   floor_responder IFACE [--rt] [--qdisc-bypass]
 *
 * --rt: SCHED_FIFO priority 80 and locked memory, as `ecsim serve --rt`.
 * --qdisc-bypass: PACKET_QDISC_BYPASS on the socket, as `ecsim serve` sets it.
 * Runs until killed; exit status 1 with a message when the socket cannot be set up.
 * Deliberately plain (C-style, no project library, no allocation), so that it costs what the
 * kernel costs. */
#include <arpa/inet.h>
#include <errno.h>
#include <linux/if_packet.h>
#include <net/if.h>
#include <sched.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/socket.h>

enum {
  kEtherTypeEtherCat = 0x88A4,
  kEthernetHeader = 14,
  kEtherCatHeader = 2,
  kDatagramHeader = 10,
  kWorkingCounter = 2,
  kLengthMask = 0x07FF, /* datagram length: 11 bits (ETG.1000.4 table 14) */
  kMoreFlag = 0x8000,   /* another datagram follows */
  kLocalMacBit = 0x02,  /* U/L bit of the first address byte */
  kRtPriority = 80,
};

/* Bumps each datagram's WKC; stops at the end of the chain or the end of the frame. */
static void bumpWorkingCounters(uint8_t* frame, size_t length) {
  size_t at = kEthernetHeader + kEtherCatHeader;
  while (at + kDatagramHeader + kWorkingCounter <= length) {
    const unsigned lenField = (unsigned)frame[at + 6] | ((unsigned)frame[at + 7] << 8);
    const size_t data = lenField & kLengthMask;
    const size_t wkcAt = at + kDatagramHeader + data;
    if (wkcAt + kWorkingCounter > length) return;
    const unsigned wkc = ((unsigned)frame[wkcAt] | ((unsigned)frame[wkcAt + 1] << 8)) + 1u;
    frame[wkcAt] = (uint8_t)wkc;
    frame[wkcAt + 1] = (uint8_t)(wkc >> 8);
    if ((lenField & kMoreFlag) == 0) return;
    at = wkcAt + kWorkingCounter;
  }
}

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: floor_responder IFACE [--rt] [--qdisc-bypass]\n");
    return 2;
  }
  int rt = 0;
  int bypass = 0;
  for (int i = 2; i < argc; ++i) {
    if (strcmp(argv[i], "--rt") == 0) {
      rt = 1;
    } else if (strcmp(argv[i], "--qdisc-bypass") == 0) {
      bypass = 1;
    } else {
      fprintf(stderr, "floor_responder: unknown option '%s' (--rt, --qdisc-bypass)\n", argv[i]);
      return 2;
    }
  }
  const unsigned ifindex = if_nametoindex(argv[1]);
  if (ifindex == 0) {
    fprintf(stderr, "floor_responder: interface '%s': %s\n", argv[1], strerror(errno));
    return 1;
  }
  const int fd = socket(AF_PACKET, SOCK_RAW, htons(kEtherTypeEtherCat));
  if (fd < 0) {
    fprintf(stderr, "floor_responder: socket(AF_PACKET): %s\n", strerror(errno));
    return 1;
  }
  const int one = 1;
  if (setsockopt(fd, SOL_PACKET, PACKET_IGNORE_OUTGOING, &one, sizeof one) != 0) {
    fprintf(stderr, "floor_responder: PACKET_IGNORE_OUTGOING: %s\n", strerror(errno));
    return 1;
  }
  if (bypass && setsockopt(fd, SOL_PACKET, PACKET_QDISC_BYPASS, &one, sizeof one) != 0) {
    fprintf(stderr, "floor_responder: PACKET_QDISC_BYPASS: %s\n", strerror(errno));
    return 1;
  }
  struct sockaddr_ll addr;
  memset(&addr, 0, sizeof addr);
  addr.sll_family = AF_PACKET;
  addr.sll_protocol = htons(kEtherTypeEtherCat);
  addr.sll_ifindex = (int)ifindex;
  if (bind(fd, (const struct sockaddr*)&addr, sizeof addr) != 0) {
    fprintf(stderr, "floor_responder: bind to '%s': %s\n", argv[1], strerror(errno));
    return 1;
  }
  if (rt) {
    struct sched_param param;
    memset(&param, 0, sizeof param);
    param.sched_priority = kRtPriority;
    if (sched_setscheduler(0, SCHED_FIFO, &param) != 0) {
      fprintf(stderr, "floor_responder: warning: SCHED_FIFO not permitted (%s)\n", strerror(errno));
    }
    if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
      fprintf(stderr, "floor_responder: warning: mlockall failed (%s)\n", strerror(errno));
    }
  }
  uint8_t frame[2048];
  for (;;) {
    const ssize_t n = recv(fd, frame, sizeof frame, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      fprintf(stderr, "floor_responder: recv: %s\n", strerror(errno));
      return 1;
    }
    if ((size_t)n < kEthernetHeader + kEtherCatHeader) continue;
    bumpWorkingCounters(frame, (size_t)n);
    frame[6] |= kLocalMacBit;
    if (send(fd, frame, (size_t)n, 0) < 0 && errno != EINTR) {
      fprintf(stderr, "floor_responder: send: %s\n", strerror(errno));
      return 1;
    }
  }
}
