/* CiA 402 client for the interop tests (SOEM v1.4.0): brings slave 1, a CiA 402 drive, to OP,
 * runs the enable sequence (shutdown 0x06, switch on 0x07, enable operation 0x0F) and a CSP
 * move of one turn through the device's own PDO mapping, which it finds the way a master
 * without a configuration file does: SOEM configures the process image from the PDO
 * assignment (0x1C12/0x1C13) and mapping objects, and this client reads the same objects over
 * SDO to find the bit offsets of the controlword, statusword, target position (0x607A, or the
 * position demand 0x6062 where the PDOs carry that), mode of operation (when mapped) and
 * position actual value inside the slave's outputs and inputs.
 * A separate program: built against SOEM's libsoem.a by the ctest fixture (build_soem.sh),
 * never linked into ecsim.
 *
 * usage: cia402_client IFNAME RXPDO TXPDO TURN
 *   RXPDO/TXPDO: PDO to assign to SM2/SM3 in PRE-OP (0: keep the device's assignment)
 *   TURN: counts of one turn
 * prints: "op", "enabled cycle N", "start S", "max_error E", "final F target T", "done"
 * exit: 0 when the move ran, 3 no slave, 4 no OP, 5 an object not in the PDOs, 6 not enabled.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ethercat.h"

static char IOmap[4096];
static uint16 rxPdo, txPdo;

struct entry
{
   int found;
   int bitOffset; /* within the slave's outputs or inputs */
};

static int sdo_u16(uint16 slave, uint16 index, uint8 sub, uint16 value)
{
   return ec_SDOwrite(slave, index, sub, FALSE, sizeof(value), &value, EC_TIMEOUTRXM);
}

static int sdo_u8(uint16 slave, uint16 index, uint8 sub, uint8 value)
{
   return ec_SDOwrite(slave, index, sub, FALSE, sizeof(value), &value, EC_TIMEOUTRXM);
}

/* PRE-OP -> SAFE-OP hook: the PDOs to use, and the interpolation period 0x60C2 = 1 ms. */
static int setup(uint16 slave)
{
   if (rxPdo != 0)
   {
      sdo_u8(slave, 0x1C12, 0, 0);
      sdo_u16(slave, 0x1C12, 1, rxPdo);
      sdo_u8(slave, 0x1C12, 0, 1);
      sdo_u8(slave, 0x1C13, 0, 0);
      sdo_u16(slave, 0x1C13, 1, txPdo);
      sdo_u8(slave, 0x1C13, 0, 1);
   }
   sdo_u8(slave, 0x60C2, 1, 1);
   sdo_u8(slave, 0x60C2, 2, (uint8)-3);
   while (EcatError) ec_elist2string(); /* a device without 0x60C2 refuses it: fine */
   return 1;
}

/* Walks the PDOs assigned in `assign` (0x1C12 or 0x1C13), filling the offsets of `indices`. */
static void locate(uint16 slave, uint16 assign, const uint16 *indices, struct entry *out, int n)
{
   uint8 count = 0;
   int size = sizeof(count);
   int bit = 0;
   if (ec_SDOread(slave, assign, 0, FALSE, &size, &count, EC_TIMEOUTRXM) <= 0) return;
   for (uint8 p = 1; p <= count; p++)
   {
      uint16 pdo = 0;
      size = sizeof(pdo);
      if (ec_SDOread(slave, assign, p, FALSE, &size, &pdo, EC_TIMEOUTRXM) <= 0) return;
      uint8 entries = 0;
      size = sizeof(entries);
      if (ec_SDOread(slave, pdo, 0, FALSE, &size, &entries, EC_TIMEOUTRXM) <= 0) return;
      for (uint8 e = 1; e <= entries; e++)
      {
         uint32 mapping = 0;
         size = sizeof(mapping);
         if (ec_SDOread(slave, pdo, e, FALSE, &size, &mapping, EC_TIMEOUTRXM) <= 0) return;
         const uint16 index = (uint16)(mapping >> 16);
         for (int i = 0; i < n; i++)
         {
            if (!out[i].found && index == indices[i])
            {
               out[i].found = 1;
               out[i].bitOffset = bit;
            }
         }
         bit += (int)(mapping & 0xFF);
      }
   }
}

static void put16(uint8 *base, const struct entry *e, uint16 v)
{
   memcpy(base + e->bitOffset / 8, &v, sizeof(v));
}
static void put32(uint8 *base, const struct entry *e, int32 v)
{
   memcpy(base + e->bitOffset / 8, &v, sizeof(v));
}
static uint16 get16(const uint8 *base, const struct entry *e)
{
   uint16 v;
   memcpy(&v, base + e->bitOffset / 8, sizeof(v));
   return v;
}
static int32 get32(const uint8 *base, const struct entry *e)
{
   int32 v;
   memcpy(&v, base + e->bitOffset / 8, sizeof(v));
   return v;
}

static void cycle(void)
{
   ec_send_processdata();
   ec_receive_processdata(EC_TIMEOUTRET);
   osal_usleep(1000);
}

int main(int argc, char *argv[])
{
   if (argc < 5)
   {
      fprintf(stderr, "usage: %s IFNAME RXPDO TXPDO TURN\n", argv[0]);
      return 2;
   }
   rxPdo = (uint16)strtoul(argv[2], NULL, 0);
   txPdo = (uint16)strtoul(argv[3], NULL, 0);
   const double turn = strtod(argv[4], NULL);
   if (!ec_init(argv[1]) || ec_config_init(FALSE) <= 0)
   {
      printf("no slaves\n");
      return 3;
   }
   ec_slave[1].PO2SOconfig = setup;
   ec_config_map(&IOmap);
   ec_statecheck(0, EC_STATE_SAFE_OP, EC_TIMEOUTSTATE);

   /* Offsets from the assignment SOEM configured (0x1C12 outputs, 0x1C13 inputs). */
   const uint16 outIdx[] = {0x6040, 0x607A, 0x6062, 0x6060};
   struct entry out[4];
   memset(out, 0, sizeof(out));
   locate(1, 0x1C12, outIdx, out, 4);
   const uint16 inIdx[] = {0x6041, 0x6064};
   struct entry in[2];
   memset(in, 0, sizeof(in));
   locate(1, 0x1C13, inIdx, in, 2);
   const struct entry *target = out[1].found ? &out[1] : &out[2];
   printf("outputs %u bytes inputs %u bytes\n", ec_slave[1].Obytes, ec_slave[1].Ibytes);
   if (!out[0].found || !target->found || !in[0].found || !in[1].found)
   {
      printf("missing: controlword %d target %d statusword %d actual %d\n", out[0].found,
             target->found, in[0].found, in[1].found);
      ec_close();
      return 5;
   }
   printf("controlword bit %d target 0x%04x bit %d statusword bit %d actual bit %d\n",
          out[0].bitOffset, target == &out[1] ? 0x607A : 0x6062, target->bitOffset,
          in[0].bitOffset, in[1].bitOffset);

   uint8 *outputs = ec_slave[1].outputs;
   uint8 *inputs = ec_slave[1].inputs;
   if (out[3].found) outputs[out[3].bitOffset / 8] = 8; /* CSP */
   ec_slave[0].state = EC_STATE_OPERATIONAL;
   cycle();
   ec_writestate(0);
   for (int i = 0; i < 400 && ec_slave[0].state != EC_STATE_OPERATIONAL; i++)
   {
      cycle();
      ec_statecheck(0, EC_STATE_OPERATIONAL, 1000);
   }
   if (ec_slave[0].state != EC_STATE_OPERATIONAL)
   {
      ec_readstate();
      printf("no OP: state 0x%x AL status 0x%04x\n", ec_slave[1].state, ec_slave[1].ALstatuscode);
      ec_close();
      return 4;
   }
   printf("op\n");

   /* Enable sequence (IEC 61800-7-201 statusword table: 0x40 switch on disabled, 0x21 ready
    * to switch on, 0x23 switched on, 0x27 operation enabled), target held at the actual. */
   int enabledAt = -1;
   for (int i = 0; i < 2000 && enabledAt < 0; i++)
   {
      cycle();
      const uint16 sw = get16(inputs, &in[0]);
      uint16 cw = 0x0006;
      if ((sw & 0x4F) == 0x08) cw = 0x0080; /* fault: reset */
      if ((sw & 0x6F) == 0x21) cw = 0x0007;
      if ((sw & 0x6F) == 0x23 || (sw & 0x6F) == 0x27) cw = 0x000F;
      put32(outputs, target, get32(inputs, &in[1]));
      put16(outputs, &out[0], cw);
      if ((sw & 0x6F) == 0x27) enabledAt = i;
   }
   if (enabledAt < 0)
   {
      printf("not enabled: statusword 0x%04x\n", get16(inputs, &in[0]));
      ec_close();
      return 6;
   }
   printf("enabled cycle %d\n", enabledAt);

   /* CSP: a cubic ramp of one turn over 1000 cycles, then 300 cycles to settle. The error is
    * taken against the target of two cycles before (one cycle out, one cycle back). */
   const int32 start = get32(inputs, &in[1]);
   printf("start %d\n", start);
   int32 history[3] = {start, start, start};
   double maxError = 0.0;
   for (int i = 1; i <= 1300; i++)
   {
      const double s = i >= 1000 ? 1.0 : i / 1000.0;
      const int32 demand = start + (int32)(turn * s * s * (3.0 - 2.0 * s) + 0.5);
      put32(outputs, target, demand);
      put16(outputs, &out[0], 0x000F);
      cycle();
      history[0] = history[1];
      history[1] = history[2];
      history[2] = demand;
      const double error = (double)get32(inputs, &in[1]) - history[0];
      if (error > maxError) maxError = error;
      if (-error > maxError) maxError = -error;
   }
   printf("max_error %.0f\n", maxError);
   printf("final %d target %d statusword 0x%04x\n", get32(inputs, &in[1]),
          start + (int32)turn, get16(inputs, &in[0]));
   ec_slave[0].state = EC_STATE_INIT;
   ec_writestate(0);
   ec_close();
   printf("done\n");
   return 0;
}
