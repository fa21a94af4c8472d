/* An IO master for the interop tests of the IO profiles (docs/devices.md): SOEM brings the
 * network to OP with the PDO mapping it reads from each slave, then every cycle (1 ms) writes a
 * pattern that changes each cycle into every slave's outputs and prints what it wrote and the
 * inputs it read, bit-exact, from SOEM's own process image (ec_slave[].inputs/outputs with
 * their start bits). The test judges the lines; this program judges nothing. A separate
 * program: built against SOEM's libsoem.a (v1.4.0, or v2.0.0 with -DSOEM_V2) by the ctest
 * fixture (build_soem.sh), never linked into ecsim.
 *
 * usage: io_client IFNAME CYCLES
 * prints: "slaves N", one "slave S name NAME ibits I obits O" per slave, "op" once every slave
 *         is in OP (else "not in OP: slave S state 0xSS" lines and exit 4), then per cycle C
 *         one line "t C SENT RECEIVED" (CLOCK_MONOTONIC in microseconds just before the
 *         process data frame was sent and just after its answer came back: whatever a slave
 *         sampled for cycle C, it sampled between the two) and per slave S with process data
 *         one line "c C s S out HEX in HEX" (HEX: the slave's
 *         bits packed from bit 0, byte 0 first, two digits a byte; "-" when it has none),
 *         "done cycles C wkc-errors E" at the end.
 * The output pattern of slave S in cycle C, byte k: (C * 7 + S * 31 + k * 17) & 0xFF, cut to
 * the slave's output bits.
 * exit: 0 after CYCLES cycles, 2 on bad arguments, 3 when no slave was found.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef SOEM_V2
#include "soem/soem.h"
static ecx_contextt ctx;
#define SLAVECOUNT (ctx.slavecount)
#define SLAVE(i) (ctx.slavelist[i])
#define GROUP0 (ctx.grouplist[0])
#define INIT(ifname) ecx_init(&ctx, ifname)
#define CONFIG_INIT() ecx_config_init(&ctx)
#define CONFIG_MAP(map) ecx_config_map_group(&ctx, map, 0)
#define CONFIG_DC() ecx_configdc(&ctx)
#define STATECHECK(s, st, t) ecx_statecheck(&ctx, s, st, t)
#define WRITESTATE(s) ecx_writestate(&ctx, s)
#define READSTATE() ecx_readstate(&ctx)
#define SEND() ecx_send_processdata(&ctx)
#define RECEIVE() ecx_receive_processdata(&ctx, EC_TIMEOUTRET)
#define CLOSE() ecx_close(&ctx)
#else
#include "ethercat.h"
#define SLAVECOUNT (ec_slavecount)
#define SLAVE(i) (ec_slave[i])
#define GROUP0 (ec_group[0])
#define INIT(ifname) ec_init(ifname)
#define CONFIG_INIT() ec_config_init(FALSE)
#define CONFIG_MAP(map) ec_config_map(map)
#define CONFIG_DC() ec_configdc()
#define STATECHECK(s, st, t) ec_statecheck(s, st, t)
#define WRITESTATE(s) ec_writestate(s)
#define READSTATE() ec_readstate()
#define SEND() ec_send_processdata()
#define RECEIVE() ec_receive_processdata(EC_TIMEOUTRET)
#define CLOSE() ec_close()
#endif

static char io_map[8192];

static long long monotonic_us(void)
{
   struct timespec t;
   clock_gettime(CLOCK_MONOTONIC, &t);
   return (long long)t.tv_sec * 1000000LL + t.tv_nsec / 1000;
}

/* Bit `bit` of the field starting at `base` + `start` bits. */
static int get_bit(const uint8 *base, unsigned start, unsigned bit)
{
   const unsigned n = start + bit;
   return (base[n / 8] >> (n % 8)) & 1;
}

static void set_bit(uint8 *base, unsigned start, unsigned bit, int on)
{
   const unsigned n = start + bit;
   if (on)
      base[n / 8] = (uint8)(base[n / 8] | (1u << (n % 8)));
   else
      base[n / 8] = (uint8)(base[n / 8] & ~(1u << (n % 8)));
}

/* Prints `bits` bits from `base` + `start` as hex bytes, bit 0 first. */
static void print_bits(const uint8 *base, unsigned start, unsigned bits)
{
   if (bits == 0 || base == NULL)
   {
      printf("-");
      return;
   }
   for (unsigned byte = 0; byte * 8 < bits; byte++)
   {
      unsigned value = 0;
      for (unsigned b = 0; b < 8 && byte * 8 + b < bits; b++)
         value |= (unsigned)get_bit(base, start, byte * 8 + b) << b;
      printf("%02x", value);
   }
}

static void write_pattern(int slave, int cycle)
{
   uint8 *out = SLAVE(slave).outputs;
   const unsigned bits = SLAVE(slave).Obits;
   if (out == NULL || bits == 0) return;
   for (unsigned bit = 0; bit < bits; bit++)
   {
      const unsigned byte = (unsigned)(cycle * 7 + slave * 31) + (bit / 8) * 17;
      set_bit(out, SLAVE(slave).Ostartbit, bit, ((byte & 0xFF) >> (bit % 8)) & 1);
   }
}

int main(int argc, char *argv[])
{
   if (argc != 3 || atoi(argv[2]) <= 0)
   {
      fprintf(stderr, "usage: %s IFNAME CYCLES\n", argv[0]);
      return 2;
   }
   const int cycles = atoi(argv[2]);
   if (!INIT(argv[1]))
   {
      printf("init on %s failed\n", argv[1]);
      return 3;
   }
   if (CONFIG_INIT() <= 0)
   {
      printf("no slaves found\n");
      CLOSE();
      return 3;
   }
   printf("slaves %d\n", SLAVECOUNT);
   CONFIG_MAP(&io_map);
   CONFIG_DC();
   for (int s = 1; s <= SLAVECOUNT; s++)
   {
      printf("slave %d name %s ibits %u obits %u\n", s, SLAVE(s).name, (unsigned)SLAVE(s).Ibits,
             (unsigned)SLAVE(s).Obits);
   }
   STATECHECK(0, EC_STATE_SAFE_OP, EC_TIMEOUTSTATE * 4);
   const int expected_wkc = (GROUP0.outputsWKC * 2) + GROUP0.inputsWKC;
   SLAVE(0).state = EC_STATE_OPERATIONAL;
   SEND();
   RECEIVE();
   WRITESTATE(0);
   for (int tries = 200; tries > 0 && SLAVE(0).state != EC_STATE_OPERATIONAL; --tries)
   {
      SEND();
      RECEIVE();
      STATECHECK(0, EC_STATE_OPERATIONAL, 50000);
   }
   if (SLAVE(0).state != EC_STATE_OPERATIONAL)
   {
      READSTATE();
      for (int i = 1; i <= SLAVECOUNT; i++)
      {
         if (SLAVE(i).state != EC_STATE_OPERATIONAL)
            printf("not in OP: slave %d state 0x%02x\n", i, SLAVE(i).state);
      }
      CLOSE();
      return 4;
   }
   printf("op\n");
   int wkc_errors = 0;
   for (int c = 0; c < cycles; c++)
   {
      for (int s = 1; s <= SLAVECOUNT; s++) write_pattern(s, c);
      const long long sent = monotonic_us();
      SEND();
      if (RECEIVE() < expected_wkc) wkc_errors++;
      printf("t %d %lld %lld\n", c, sent, monotonic_us());
      for (int s = 1; s <= SLAVECOUNT; s++)
      {
         if (SLAVE(s).Obits == 0 && SLAVE(s).Ibits == 0) continue;
         printf("c %d s %d out ", c, s);
         print_bits(SLAVE(s).outputs, SLAVE(s).Ostartbit, SLAVE(s).Obits);
         printf(" in ");
         print_bits(SLAVE(s).inputs, SLAVE(s).Istartbit, SLAVE(s).Ibits);
         printf("\n");
      }
      osal_usleep(1000);
   }
   printf("done cycles %d wkc-errors %d\n", cycles, wkc_errors);
   SLAVE(0).state = EC_STATE_INIT;
   WRITESTATE(0);
   CLOSE();
   return 0;
}
